// `droverctl pause (VEHICLE | --all) [--reason TEXT] [--wait S]`: an operator pauses one
// vehicle, or every vehicle whose logical agent is alive (drover/logical/pause,
// docs/logical-agent.md "Pausing a vehicle"): it drives the moves already commanded, stops on
// a vertex and begins nothing new until resumed. With --wait, also waits until the logical
// agents report the vehicles standing paused.
// `droverctl resume (VEHICLE | --all)`: lets them go on.
// Exit 0: done (with --wait: all standing paused within S); 1: a vehicle refused (its
// journal could not store it), did not answer (with --all), or did not stand paused within
// --wait; 2: bad usage; 3: no logical agent of that vehicle (with --all: none at all)
// answered.

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "agents/cli/agent_discovery.hpp"
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
  std::string vehicle;  ///< empty with --all
  bool all = false;
  std::string reason;
  double wait_seconds = 0;
};

/// Follows whether each vehicle stands paused, from its logical agent's state.
class PausedWatch {
 public:
  void on_state(const msg::VehicleState& state) {
    std::lock_guard lock(mutex_);
    standing_[state.vehicle()] = state.paused() && state.state() == msg::VEHICLE_PAUSED;
    changed_.notify_all();
  }
  /// Waits until every one of `vehicles` stands paused, at most `timeout`.
  /// \return those that do not stand paused then.
  std::vector<std::string> wait(const std::vector<std::string>& vehicles, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return not_standing(vehicles).empty(); });
    return not_standing(vehicles);
  }

 private:
  /// \pre mutex_ is held
  std::vector<std::string> not_standing(const std::vector<std::string>& vehicles) const {
    std::vector<std::string> out;
    for (const auto& vehicle : vehicles) {
      const auto found = standing_.find(vehicle);
      if (found == standing_.end() || !found->second) out.push_back(vehicle);
    }
    return out;
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<std::string, bool> standing_;
};

/// The vehicles of the live logical agents on the participant's domain, sorted.
Result<std::vector<std::string>> live_vehicles(dds::Participant& participant, std::chrono::milliseconds timeout) {
  const auto agents = discover_live_agents(participant, timeout);
  if (!agents) return unexpected(agents.error());
  std::vector<std::string> vehicles;
  for (const auto& agent : *agents) {
    if (agent.kind != "logical" || !agent.alive) continue;
    vehicles.insert(vehicles.end(), agent.owns.begin(), agent.owns.end());
  }
  std::sort(vehicles.begin(), vehicles.end());
  vehicles.erase(std::unique(vehicles.begin(), vehicles.end()), vehicles.end());
  return vehicles;
}

int run_pause(const PauseArguments& arguments, bool pause) {
  if (arguments.all == !arguments.vehicle.empty()) {
    std::cerr << "error: name one VEHICLE or give --all\n";
    return kExitBadInput;
  }
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  // The watch and its reader before the requests: the state that answers one may come at once.
  PausedWatch watch;
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
  std::vector<std::string> vehicles{arguments.vehicle};
  if (arguments.all) {
    auto live = live_vehicles(**participant, arguments.dds.timeout());
    if (!live) {
      std::cerr << "error: " << live.error().message << "\n";
      return kExitFailure;
    }
    if (live->empty()) {
      std::cerr << "error: no logical agent answered on domain " << arguments.dds.domain_id << " within "
                << arguments.dds.timeout_seconds << " s\n";
      return kExitNoAnswer;
    }
    vehicles = std::move(*live);
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
  // Every vehicle is asked even when one fails: an operator pausing the fleet wants as many
  // of them paused as can be.
  std::vector<std::string> done;
  int failure = kExitOk;
  for (const auto& vehicle : vehicles) {
    int code = kExitOk;
    if (!call_logical_agent(**client, arguments.dds, vehicle, request, pause ? "was not paused" : "was not resumed",
                            code)) {
      failure = arguments.all ? kExitFailure : code;
      continue;
    }
    done.push_back(vehicle);
    std::cout << "vehicle '" << vehicle << "' " << (pause ? "paused: it stops at the next vertex it can" : "resumed")
              << "\n";
  }
  if (pause && arguments.wait_seconds > 0 && !done.empty()) {
    const auto late = watch.wait(done, std::chrono::milliseconds(static_cast<std::int64_t>(arguments.wait_seconds * 1000)));
    states.reset();  // before the watch it calls
    for (const auto& vehicle : done) {
      if (std::find(late.begin(), late.end(), vehicle) == late.end()) {
        std::cout << "vehicle '" << vehicle << "' stands paused\n";
      } else {
        std::cerr << "error: vehicle '" << vehicle << "' not standing paused within " << arguments.wait_seconds
                  << " s\n";
        failure = kExitFailure;
      }
    }
  }
  return failure;
}

}  // namespace

void add_pause_command(CLI::App& app, CommandContext& context) {
  auto paused = std::make_shared<PauseArguments>();
  auto* pause = app.add_subcommand(
      "pause", "Pause a vehicle, or all: it stops at the next vertex it can and begins nothing new until resumed");
  pause->add_option("vehicle", paused->vehicle, "The vehicle id");
  pause->add_flag("--all", paused->all, "Every vehicle whose logical agent is alive");
  pause->add_option("--reason", paused->reason, "Why (shown in droverctl vehicles)");
  pause->add_option("--wait", paused->wait_seconds,
                    "Also wait up to S seconds until the vehicles stand paused (exit 1 if one does not)")
      ->transform(cli::non_negative());
  add_dds_tool_options(*pause, paused->dds, 5.0);
  pause->callback([paused, &context] { context.exit_code = run_pause(*paused, true); });

  auto resumed = std::make_shared<PauseArguments>();
  auto* resume = app.add_subcommand("resume", "Resume a paused vehicle, or all");
  resume->add_option("vehicle", resumed->vehicle, "The vehicle id");
  resume->add_flag("--all", resumed->all, "Every vehicle whose logical agent is alive");
  add_dds_tool_options(*resume, resumed->dds, 5.0);
  resume->callback([resumed, &context] { context.exit_code = run_pause(*resumed, false); });
}

}  // namespace drover::cli
