#pragma once
// The type-erased part of a service client: the request writer, the reply reader filtered
// on this agent's id, choosing a matched server, and correlating replies with requests
// through the sample identity. ServiceClient<Req, Rep> wraps it.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/common/SampleIdentity.h>

#include "drover/common/result.hpp"
#include "drover/dds/detail/reader_core.hpp"
#include "drover/dds/detail/writer_core.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/service_topics.hpp"

namespace drover::dds {

/// Counters of a service client, for diagnostics and tests.
struct ClientStats {
  std::uint64_t requests_sent = 0;
  std::uint64_t replies_received = 0;
  /// Replies that arrived after their call had given up (timed out or failed).
  std::uint64_t late_replies = 0;
  /// Replies that reached this client but answer another client of the same agent id and
  /// service (the content filter only separates agent ids).
  std::uint64_t replies_for_other_clients = 0;
};

namespace detail {

using Deadline = std::chrono::steady_clock::time_point;

/// A server matched on both topics of a service.
struct ServerRef {
  eprosima::fastrtps::rtps::GuidPrefix_t participant;
  std::string name;  ///< its agent id
};

class ClientCore {
 public:
  /// \return the client, or the endpoint errors (see WriterCore, ReaderCore).
  static Result<std::unique_ptr<ClientCore>> create(Participant& participant, ServiceTopics topics,
                                                    eprosima::fastdds::dds::TypeSupport request_type,
                                                    eprosima::fastdds::dds::TypeSupport reply_type);
  /// Deletes the endpoints first; calls still waiting must have returned (contract).
  ~ClientCore();

  /// Waits until a server named `responder` (any server when empty) is matched on both
  /// the request and the reply topic, so that neither the request nor the reply can be
  /// lost to discovery. Among several servers it picks them in turn.
  /// \return the server, or timeout ("no server ... matched within N ms").
  Result<ServerRef> wait_for_server(const std::string& responder, Deadline deadline,
                                    std::chrono::milliseconds timeout);

  /// Writes `request` (its header already addressed to `server`) and waits for the reply.
  /// \return the reply buffer (made by the reply type support), or timeout (no reply in
  ///         time), or unavailable (the server went away), or io (write failed).
  Result<std::shared_ptr<void>> send(void* request, const ServerRef& server, Deadline deadline,
                                     std::chrono::milliseconds timeout);

  ClientStats stats() const;
  const std::string& service_name() const noexcept { return topics_.name; }
  /// This client's reply reader as RequestHeader.reply_reader names it (its entity id).
  std::uint32_t reply_reader_id() const noexcept { return reply_reader_id_; }

 private:
  struct Call {
    ServerRef server;
    std::shared_ptr<void> reply;
    std::optional<Error> error;
  };

  ClientCore(Participant& participant, ServiceTopics topics);
  std::optional<ServerRef> pick_server(const std::string& responder);
  void on_reply(std::shared_ptr<void>& reply, const eprosima::fastdds::dds::SampleInfo& info);
  void on_match_change();

  Participant& participant_;
  ServiceTopics topics_;

  std::mutex write_mutex_;  // one write-and-register at a time: see send()

  mutable std::mutex state_mutex_;
  std::condition_variable state_changed_;
  std::map<eprosima::fastrtps::rtps::SampleIdentity, Call*> pending_;
  // Replies that overtook the registration of their call, by sequence number.
  std::map<eprosima::fastrtps::rtps::SequenceNumber_t, std::shared_ptr<void>> early_replies_;
  eprosima::fastrtps::rtps::SequenceNumber_t last_registered_;
  eprosima::fastrtps::rtps::GUID_t writer_guid_;
  std::uint32_t reply_reader_id_ = 0;
  std::uint64_t next_server_ = 0;
  ClientStats stats_;

  // Declared last: destroyed first, so that no endpoint callback runs on a dead client.
  std::unique_ptr<ReaderCore> reply_reader_;
  std::unique_ptr<WriterCore> request_writer_;
};

}  // namespace detail
}  // namespace drover::dds
