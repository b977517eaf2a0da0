#pragma once
// Typed client of a request/reply service (docs/dds.md "Request/reply"). Requests go out
// only once a server is matched on both topics; replies are correlated with requests by
// sample identity and reach only this agent (content filter on header.requester).

#include <chrono>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

#include "drover/common/result.hpp"
#include "drover/dds/detail/client_core.hpp"
#include "drover/dds/message_types.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/service_topics.hpp"

namespace drover::dds {

/// Req and Rep are IDL structs whose first member is `RequestHeader header`.
/// Thread-safe: any number of threads may call() at once. Must be destroyed before its
/// Participant and after every call() has returned.
template <class Req, class Rep>
class ServiceClient {
 public:
  /// A client of service drover/<area>/<service>.
  /// \return the client, or invalid_argument (bad names), or the endpoint errors.
  static Result<std::unique_ptr<ServiceClient>> create(Participant& participant,
                                                       std::string_view area,
                                                       std::string_view service) {
    auto topics = service_topics(area, service);
    if (!topics) return unexpected(topics.error());
    auto core = detail::ClientCore::create(participant, std::move(*topics), type_support<Req>(),
                                           type_support<Rep>());
    if (!core) return unexpected(core.error());
    return std::unique_ptr<ServiceClient>(new ServiceClient(participant, std::move(*core)));
  }

  /// Sends `request` to the server `responder` (an agent id; empty: any server, taken in
  /// turn when several serve) and waits for its reply. Sets request.header: requester =
  /// this agent, responder = the chosen server, reply_reader = this client's reply reader.
  /// \param timeout bounds the whole call: waiting for a server, then for the reply.
  /// \return the reply (whose `error` member carries the server's verdict), or
  ///         timeout "no server ... matched within ..." (nobody serves), or
  ///         timeout "server 'x' did not reply ... within ..." (no reply in time), or
  ///         unavailable (the server went away while we waited), or io (write failed).
  Result<Rep> call(Req request, std::chrono::milliseconds timeout, const std::string& responder = {}) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    auto server = core_->wait_for_server(responder, deadline, timeout);
    if (!server) return unexpected(std::move(server).error());
    request.header().requester(participant_.agent_id());
    request.header().responder(server->name);
    request.header().reply_reader(core_->reply_reader_id());
    auto reply = core_->send(&request, *server, deadline, timeout);
    if (!reply) return unexpected(std::move(reply).error());
    return std::move(*static_cast<Rep*>(reply->get()));
  }

  /// Waits until a server (named `responder`, or any) is matched. \return its agent id,
  /// or timeout.
  Result<std::string> wait_for_server(std::chrono::milliseconds timeout,
                                      const std::string& responder = {}) {
    auto server = core_->wait_for_server(responder, std::chrono::steady_clock::now() + timeout, timeout);
    if (!server) return unexpected(std::move(server).error());
    return std::move(server->name);
  }

  ClientStats stats() const { return core_->stats(); }

 private:
  ServiceClient(Participant& participant, std::unique_ptr<detail::ClientCore> core)
      : participant_(participant), core_(std::move(core)) {}

  Participant& participant_;
  std::unique_ptr<detail::ClientCore> core_;
};

}  // namespace drover::dds
