// dds_test_peer: a real agent process for the DDS layer's tests. On a given domain it
// serves the echo service drover/diagnostics/ping and/or publishes a heartbeat, until
// SIGINT / SIGTERM, then deletes its entities and exits 0.
//
// Echo service: a request's text is echoed with its payload, except
//   "hold:KEY"     the reply is deferred: kept until a "release:KEY" request arrives;
//   "release:KEY"  answers the held request KEY ("released KEY"), then this one
//                  ("released"); not_found when nothing is held under KEY.

#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "diagnostics.h"
#include "drover/common/clock.hpp"
#include "drover/dds/heartbeat_publisher.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/service_server.hpp"
#include "drover/dds/shutdown_signal.hpp"
#include "drover/dds/wire_error.hpp"

namespace {

using drover::dds::ReplyHandle;
using drover::msg::PingReply;
using drover::msg::PingRequest;

constexpr std::string_view kHold = "hold:";
constexpr std::string_view kRelease = "release:";

/// The echo handler. Runs on the server's thread only, so `held` needs no lock.
void serve_ping(std::map<std::string, ReplyHandle<PingReply>>& held, const PingRequest& request,
                ReplyHandle<PingReply> reply) {
  const std::string& text = request.text();
  if (text.rfind(kHold, 0) == 0) {
    held.insert_or_assign(text.substr(kHold.size()), std::move(reply));
    return;
  }
  PingReply answer;
  if (text.rfind(kRelease, 0) == 0) {
    const std::string key = text.substr(kRelease.size());
    auto it = held.find(key);
    if (it == held.end()) {
      (void)reply.send_error({drover::ErrorCode::not_found, "nothing held under '" + key + "'"});
      return;
    }
    PingReply released;
    released.text("released " + key);
    if (auto sent = it->second.send(std::move(released)); !sent) {
      std::cerr << "dds_test_peer: " << sent.error().message << "\n";
    }
    held.erase(it);
    answer.text("released");
  } else {
    answer.text(text);
    answer.payload(request.payload());
  }
  if (auto sent = reply.send(std::move(answer)); !sent) {
    std::cerr << "dds_test_peer: " << sent.error().message << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Test peer of the DDS layer's tests"};
  drover::dds::ParticipantOptions participant_options;
  bool echo = false;
  std::string heartbeat_kind;
  std::vector<std::string> owns;
  app.add_option("--domain", participant_options.domain_id, "DDS domain id")->required();
  app.add_option("--id", participant_options.agent_id, "agent id")->required();
  app.add_flag("--echo", echo, "serve drover/diagnostics/ping");
  app.add_option("--heartbeat", heartbeat_kind, "publish a heartbeat of this agent kind");
  app.add_option("--owns", owns, "what the heartbeat says the agent owns");
  CLI11_PARSE(app, argc, argv);

  if (auto installed = drover::dds::install_shutdown_handlers(); !installed) {
    std::cerr << "dds_test_peer: " << installed.error().message << "\n";
    return 1;
  }
  auto participant = drover::dds::Participant::create(participant_options);
  if (!participant) {
    std::cerr << "dds_test_peer: " << participant.error().message << "\n";
    return 1;
  }

  std::map<std::string, ReplyHandle<PingReply>> held;
  std::unique_ptr<drover::dds::ServiceServer<PingRequest, PingReply>> server;
  if (echo) {
    auto created = drover::dds::ServiceServer<PingRequest, PingReply>::create(
        **participant, "diagnostics", "ping",
        [&held](const PingRequest& request, ReplyHandle<PingReply> reply) {
          serve_ping(held, request, std::move(reply));
        });
    if (!created) {
      std::cerr << "dds_test_peer: " << created.error().message << "\n";
      return 1;
    }
    server = std::move(*created);
  }

  std::unique_ptr<drover::dds::HeartbeatPublisher> heartbeat;
  if (!heartbeat_kind.empty()) {
    drover::dds::HeartbeatOptions options;
    options.kind = heartbeat_kind;
    options.owns = owns;
    auto created = drover::dds::HeartbeatPublisher::create(**participant, drover::SharedClock::wall(),
                                                           options);
    if (!created) {
      std::cerr << "dds_test_peer: " << created.error().message << "\n";
      return 1;
    }
    heartbeat = std::move(*created);
  }

  drover::dds::wait_for_shutdown();
  heartbeat.reset();
  server.reset();  // held replies then fail with unavailable: their server is gone
  held.clear();
  participant->reset();
  return 0;
}
