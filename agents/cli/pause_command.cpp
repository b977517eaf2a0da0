// `droverctl pause VEHICLE [--reason TEXT] [--wait S]`: an operator pauses one vehicle
// (drover/logical/pause, docs/logical-agent.md "Pausing a vehicle"): it drives the moves
// already commanded, stops on a vertex and begins nothing new until resumed. With --wait,
// also waits until its logical agent reports it standing paused.
// `droverctl resume VEHICLE`: lets it go on.
// Exit 0: done (with --wait: standing paused within S); 1: refused (the journal could not
// store it), or not standing paused within --wait; 3: no logical agent of that vehicle
// answered.

#include <chrono>
#include <condition_variable>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>

#include "agents/cli/command.hpp"
#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "agents/cli/logical_agent_call.hpp"
#include "drover/dds/reader.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/logical_agent/names.hpp"

namespace drover::cli {
namespace {

struct PauseArguments {
  DdsToolOptions dds;
  std::string vehicle;
  std::string reason;
  double wait_seconds = 0;
};

/// Waits until one vehicle's state says it stands paused.
class PausedWatch {
 public:
  explicit PausedWatch(std::string vehicle) : vehicle_(std::move(vehicle)) {}
  void on_state(const msg::VehicleState& state) {
    if (state.vehicle() != vehicle_ || !state.paused() || state.state() != msg::VEHICLE_PAUSED) return;
    std::lock_guard lock(mutex_);
    standing_ = true;
    changed_.notify_all();
  }
  bool wait(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return standing_; });
  }

 private:
  const std::string vehicle_;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool standing_ = false;
};

int run_pause(const PauseArguments& arguments, bool pause) {
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  // The watch and its reader before the request: the state that answers it may come at once.
  PausedWatch watch(arguments.vehicle);
  std::unique_ptr<dds::Reader<msg::VehicleState>> states;
  if (pause && arguments.wait_seconds > 0) {
    auto reader = dds::Reader<msg::VehicleState>::create(
        **participant, logical_agent::kVehicleStateTopic, [&watch](const msg::VehicleState& state) { watch.on_state(state); });
    if (!reader) {
      std::cerr << "error: " << reader.error().message << "\n";
      return kExitFailure;
    }
    states = std::move(*reader);
  }
  auto client = dds::ServiceClient<msg::VehiclePauseRequest, msg::StatusReply>::create(
      **participant, logical_agent::kServiceArea, logical_agent::kPauseService);
  if (!client) {
    std::cerr << "error: " << client.error().message << "\n";
    return kExitFailure;
  }
  msg::VehiclePauseRequest request;
  request.paused(pause);
  request.reason(arguments.reason);
  int code = kExitOk;
  if (!call_logical_agent(**client, arguments.dds, arguments.vehicle, request,
                          pause ? "was not paused" : "was not resumed", code)) {
    return code;
  }
  if (!pause) {
    std::cout << "vehicle '" << arguments.vehicle << "' resumed\n";
    return kExitOk;
  }
  std::cout << "vehicle '" << arguments.vehicle << "' paused: it stops at the next vertex it can\n";
  if (arguments.wait_seconds <= 0) return kExitOk;
  if (!watch.wait(std::chrono::milliseconds(static_cast<std::int64_t>(arguments.wait_seconds * 1000)))) {
    std::cerr << "error: vehicle '" << arguments.vehicle << "' not standing paused within " << arguments.wait_seconds
              << " s\n";
    states.reset();  // before the watch it calls
    return kExitFailure;
  }
  states.reset();
  std::cout << "vehicle '" << arguments.vehicle << "' stands paused\n";
  return kExitOk;
}

}  // namespace

void add_pause_command(CLI::App& app, CommandContext& context) {
  auto paused = std::make_shared<PauseArguments>();
  auto* pause = app.add_subcommand(
      "pause", "Pause a vehicle: it stops at the next vertex it can and begins nothing new until resumed");
  pause->add_option("vehicle", paused->vehicle, "The vehicle id")->required();
  pause->add_option("--reason", paused->reason, "Why (shown in droverctl vehicles)");
  pause->add_option("--wait", paused->wait_seconds,
                    "Also wait up to S seconds until the vehicle stands paused (exit 1 if it does not)")
      ->transform(cli::non_negative());
  add_dds_tool_options(*pause, paused->dds, 5.0);
  pause->callback([paused, &context] { context.exit_code = run_pause(*paused, true); });

  auto resumed = std::make_shared<PauseArguments>();
  auto* resume = app.add_subcommand("resume", "Resume a paused vehicle");
  resume->add_option("vehicle", resumed->vehicle, "The vehicle id")->required();
  add_dds_tool_options(*resume, resumed->dds, 5.0);
  resume->callback([resumed, &context] { context.exit_code = run_pause(*resumed, false); });
}

}  // namespace drover::cli
