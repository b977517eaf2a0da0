#pragma once
// The type-erased part of a service server: the request reader and the reply channel that
// reply handles write through, possibly long after the request (deferred replies).

#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/common/SampleIdentity.h>

#include "drover/common/result.hpp"
#include "drover/dds/detail/reader_core.hpp"
#include "drover/dds/detail/writer_core.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/service_topics.hpp"

namespace drover::dds::detail {

/// Where a reply goes: the request it answers and the reader that waits for it.
struct ReplyTarget {
  eprosima::fastrtps::rtps::SampleIdentity request;
  /// The requester's reply reader; its entity id is unknown when the request did not name
  /// it (RequestHeader.reply_reader 0), and then any reader of its participant will do.
  eprosima::fastrtps::rtps::GUID_t reply_reader;
  std::string requester;  ///< the requester's agent id, for messages
};

/// The reply writer of a server, shared by the server and its outstanding reply handles.
/// Thread-safe. After close(), writes fail with unavailable.
class ReplyChannel {
 public:
  ReplyChannel(std::string service_name, std::chrono::milliseconds match_timeout);
  ~ReplyChannel();

  /// Takes ownership of the reply writer (see ServerCore::create).
  void attach(std::unique_ptr<WriterCore> writer);
  /// Deletes the reply writer, waiting for a write in progress.
  void close();
  /// Wakes writers waiting for a match (the reply writer's match hook).
  void notify_match_change();

  /// Writes `reply` as the answer to `target`, once the requester's reply reader is
  /// matched (a reply written earlier would be lost).
  /// \return success, or timeout (the requester's reply reader did not match within the
  ///         match timeout), or unavailable (closed), or io (write failed).
  Status write(void* reply, const ReplyTarget& target);

  const std::string& service_name() const noexcept { return service_name_; }

 private:
  std::string service_name_;
  std::chrono::milliseconds match_timeout_;
  std::mutex mutex_;
  std::condition_variable match_changed_;
  std::unique_ptr<WriterCore> writer_;
};

class ServerCore {
 public:
  /// Gets each request, on the server's own thread, one at a time.
  using RequestHandler =
      std::function<void(void* request, const eprosima::fastdds::dds::SampleInfo& info,
                         const std::shared_ptr<ReplyChannel>& channel)>;

  /// \return the server, or the endpoint errors (see WriterCore, ReaderCore).
  static Result<std::unique_ptr<ServerCore>> create(Participant& participant, ServiceTopics topics,
                                                    eprosima::fastdds::dds::TypeSupport request_type,
                                                    eprosima::fastdds::dds::TypeSupport reply_type,
                                                    std::chrono::milliseconds reply_match_timeout,
                                                    RequestHandler handler);
  /// Stops taking requests (waits for a running handler), then closes the reply channel:
  /// outstanding reply handles fail with unavailable from then on.
  ~ServerCore();

  std::size_t matched_clients() const;

 private:
  ServerCore() = default;
  std::shared_ptr<ReplyChannel> channel_;
  std::unique_ptr<ReaderCore> request_reader_;
};

}  // namespace drover::dds::detail
