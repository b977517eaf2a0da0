#pragma once
// Typed server of a request/reply service (docs/dds.md "Request/reply"). Each request is
// handed to the handler with a ReplyHandle; the handler answers at once or keeps the
// handle and answers later (an allocation queued until it is granted).

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

#include <spdlog/spdlog.h>

#include "drover/common/result.hpp"
#include "drover/dds/detail/server_core.hpp"
#include "drover/dds/message_types.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/service_topics.hpp"
#include "drover/dds/wire_error.hpp"

namespace drover::dds {

/// The promise of one reply. Move-only. Any thread may send it, once. A handle destroyed
/// without sending answers with ERROR_INTERNAL, so a requester never waits in vain.
template <class Rep>
class ReplyHandle {
 public:
  ReplyHandle(std::shared_ptr<detail::ReplyChannel> channel, detail::ReplyTarget target,
              std::string responder)
      : channel_(std::move(channel)), target_(std::move(target)), responder_(std::move(responder)) {}
  ReplyHandle(ReplyHandle&& other) noexcept = default;
  ReplyHandle& operator=(ReplyHandle&& other) noexcept {
    if (this != &other) {
      abandon();
      channel_ = std::move(other.channel_);
      target_ = std::move(other.target_);
      responder_ = std::move(other.responder_);
    }
    return *this;
  }
  ~ReplyHandle() { abandon(); }

  /// The agent id of the requester.
  const std::string& requester() const noexcept { return target_.requester; }
  /// Whether the reply is still to be sent.
  bool pending() const noexcept { return channel_ != nullptr; }

  /// Sends `reply` (its header is filled in; its `error` is sent as set, ERROR_NONE by
  /// default). \return success, or invalid_argument (already sent), or the channel's
  /// error (timeout: the requester's reply reader never matched; unavailable: the
  /// server was destroyed).
  Status send(Rep reply) {
    if (!channel_) return fail(ErrorCode::invalid_argument, "reply already sent");
    auto channel = std::move(channel_);
    reply.header().requester(target_.requester);
    reply.header().responder(responder_);
    reply.header().reply_reader(target_.reply_reader.entityId.to_uint32());
    return channel->write(&reply, target_);
  }

  /// Sends a reply that carries only `error`.
  Status send_error(const Error& error) {
    Rep reply;
    reply.error(to_wire(error));
    return send(std::move(reply));
  }

 private:
  void abandon() {
    if (!channel_) return;
    const std::string service = channel_->service_name();
    auto sent = send_error(Error{ErrorCode::internal, "server '" + responder_ + "' of '" + service +
                                                          "' dropped the request without answering"});
    if (!sent) spdlog::warn("{}: {}", service, sent.error().message);
  }

  std::shared_ptr<detail::ReplyChannel> channel_;
  detail::ReplyTarget target_;
  std::string responder_;
};

struct ServerOptions {
  /// How long a reply waits for the requester's reply reader to match before it fails.
  std::chrono::milliseconds reply_match_timeout{5000};
};

/// Req and Rep are IDL structs whose first member is `RequestHeader header`; Rep also has
/// `Error error`. Must be destroyed before its Participant and not from inside its handler.
template <class Req, class Rep>
class ServiceServer {
 public:
  /// Gets each request addressed to this agent (or to any server), on the server's own
  /// thread, one at a time; it may block and may call other services.
  using Handler = std::function<void(const Req& request, ReplyHandle<Rep> reply)>;

  /// Serves drover/<area>/<service> as this participant's agent.
  /// \return the server, or invalid_argument (bad names), or the endpoint errors.
  static Result<std::unique_ptr<ServiceServer>> create(Participant& participant, std::string_view area,
                                                       std::string_view service, Handler handler,
                                                       ServerOptions options = {}) {
    auto topics = service_topics(area, service);
    if (!topics) return unexpected(topics.error());
    auto core = detail::ServerCore::create(
        participant, std::move(*topics), type_support<Req>(), type_support<Rep>(),
        options.reply_match_timeout,
        [handler = std::move(handler), self_id = participant.agent_id()](
            void* sample, const eprosima::fastdds::dds::SampleInfo& info,
            const std::shared_ptr<detail::ReplyChannel>& channel) {
          const Req& request = *static_cast<const Req*>(sample);
          const std::string& responder = request.header().responder();
          if (!responder.empty() && responder != self_id) return;  // addressed to another server
          const eprosima::fastrtps::rtps::GUID_t reply_reader(info.sample_identity.writer_guid().guidPrefix,
                                                              request.header().reply_reader());
          detail::ReplyTarget target{info.sample_identity, reply_reader, request.header().requester()};
          handler(request, ReplyHandle<Rep>(channel, std::move(target), self_id));
        });
    if (!core) return unexpected(core.error());
    return std::unique_ptr<ServiceServer>(new ServiceServer(std::move(*core)));
  }

  /// Number of client request writers matched.
  std::size_t matched_clients() const { return core_->matched_clients(); }

 private:
  explicit ServiceServer(std::unique_ptr<detail::ServerCore> core) : core_(std::move(core)) {}
  std::unique_ptr<detail::ServerCore> core_;
};

}  // namespace drover::dds
