// `droverctl pause (VEHICLE | --all) [--reason TEXT] [--wait S]`: an operator pauses one
// vehicle, or every vehicle whose logical agent is alive (drover/logical/pause,
// docs/logical-agent.md "Pausing a vehicle"): it drives the moves already commanded, stops on
// a vertex and begins nothing new until resumed. With --wait, also waits until the logical
// agents report the vehicles standing paused.
// `droverctl resume (VEHICLE | --all [--reason TEXT])`: lets them go on.
// With --all, a vehicle paused already is left as it is (its reason kept), and `resume --all
// --reason TEXT` resumes only those paused for that reason: a fleet-wide pause and its end
// never lift the pause an operator put on one vehicle for a reason of its own.
// Exit 0: done (with --wait: all standing paused within S); 1: a vehicle refused (its
// journal could not store it), did not answer (with --all), or did not stand paused within
// --wait; 2: bad usage; 3: no logical agent of that vehicle (with --all: none at all)
// answered.

#include <algorithm>
#include <chrono>
#include <future>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "agents/cli/agent_discovery.hpp"
#include "agents/cli/command.hpp"
#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "agents/cli/logical_agent_call.hpp"
#include "agents/cli/vehicle_states.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/logical_agent/names.hpp"

namespace drover::cli {
namespace {

struct PauseArguments {
  DdsToolOptions dds;
  std::string vehicle;  ///< empty with --all
  bool all = false;
  std::string reason;  ///< pause: why; resume --all: only the vehicles paused for this
  double wait_seconds = 0;
};

using PauseClient = dds::ServiceClient<msg::VehiclePauseRequest, msg::StatusReply>;

bool standing_paused(const VehicleStates::States& states, const std::string& vehicle) {
  const auto found = states.find(vehicle);
  return found != states.end() && found->second.paused() && found->second.state() == msg::VEHICLE_PAUSED;
}

std::string reason_text(const msg::VehicleState& state) {
  return state.pause_reason().empty() ? "no reason given" : "'" + state.pause_reason() + "'";
}

/// The vehicles `--all` asks, from the live logical agents and their states (`known`); says
/// on standard output which it leaves as they are and why. `standing` gets the vehicles
/// paused already (a --wait waits for them too); `unknown` whether a vehicle was left out
/// because its state did not arrive (said on standard error).
std::vector<std::string> vehicles_to_ask(const PauseArguments& arguments, bool pause,
                                         const std::vector<std::string>& live, const VehicleStates::States& known,
                                         std::vector<std::string>& standing, bool& unknown) {
  std::vector<std::string> asked;
  unknown = false;
  for (const auto& vehicle : live) {
    const auto found = known.find(vehicle);
    if (found == known.end()) {
      // Without its state, a pause could replace the reason of a pause an operator put on
      // it alone (which a later `resume --all --reason` would then lift), and a selective
      // resume cannot choose: it is not asked, and the command fails.
      std::cerr << "error: vehicle '" << vehicle << "' not " << (pause ? "paused" : "resumed") << ": its state did not "
                << "arrive within " << arguments.dds.timeout_seconds << " s, so whether it is paused already (and "
                << "why) is unknown; try again\n";
      unknown = true;
      continue;
    }
    if (pause && found->second.paused()) {
      std::cout << "vehicle '" << vehicle << "' already paused (" << reason_text(found->second) << "): left as it is\n";
      standing.push_back(vehicle);
      continue;
    } else if (!pause && !found->second.paused()) {
      std::cout << "vehicle '" << vehicle << "' not paused\n";
      continue;
    } else if (!pause && !arguments.reason.empty() && found->second.pause_reason() != arguments.reason) {
      std::cout << "vehicle '" << vehicle << "' left paused (" << reason_text(found->second) << ")\n";
      continue;
    }
    asked.push_back(vehicle);
  }
  return asked;
}

/// Asks every vehicle at once (a logical agent that does not answer delays none of the
/// others), then prints the answers in the order of `vehicles`. \return the vehicles that
/// accepted; `failure` gets the exit code of a failure (kExitOk when none).
std::vector<std::string> ask_all(PauseClient& client, const PauseArguments& arguments, bool pause,
                                 const std::vector<std::string>& vehicles, int& failure) {
  msg::VehiclePauseRequest request;
  request.paused(pause);
  if (pause) request.reason(arguments.reason);
  const std::string refused = pause ? "was not paused" : "was not resumed";
  std::vector<std::future<LogicalAgentAnswer<msg::StatusReply>>> answers;
  for (const auto& vehicle : vehicles) {
    answers.push_back(std::async(std::launch::async, [&, vehicle] {
      return ask_logical_agent(client, arguments.dds, vehicle, request, refused);
    }));
  }
  std::vector<std::string> accepted;
  failure = kExitOk;
  for (std::size_t i = 0; i < vehicles.size(); ++i) {
    const auto answer = answers[i].get();
    if (!answer.reply) {
      std::cerr << "error: " << answer.error << "\n";
      // Of several vehicles, one not answering is a failure of the command, not "nobody".
      failure = arguments.all ? kExitFailure : answer.exit_code;
      continue;
    }
    accepted.push_back(vehicles[i]);
    std::cout << "vehicle '" << vehicles[i] << "' "
              << (pause ? "paused: it stops at the next vertex it can" : "resumed") << "\n";
  }
  return accepted;
}

int run_pause(const PauseArguments& arguments, bool pause) {
  if (arguments.all == !arguments.vehicle.empty()) {
    std::cerr << "error: name one VEHICLE or give --all\n";
    return kExitBadInput;
  }
  if (!pause && !arguments.reason.empty() && !arguments.all) {
    std::cerr << "error: --reason on resume chooses among --all; a named vehicle is resumed whatever its reason\n";
    return kExitBadInput;
  }
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  // The states before the requests: the state that answers one may come at once.
  std::unique_ptr<VehicleStates> states;
  if (arguments.all || (pause && arguments.wait_seconds > 0)) {
    auto follower = VehicleStates::create(**participant);
    if (!follower) {
      std::cerr << "error: " << follower.error().message << "\n";
      return kExitFailure;
    }
    states = std::move(*follower);
  }
  std::vector<std::string> asked{arguments.vehicle};
  std::vector<std::string> standing;  // paused already, left as they are
  bool unknown_state = false;          // a vehicle left out: its state did not arrive
  if (arguments.all) {
    // Every live logical agent, and its vehicle's state (what decides whether it is asked).
    const auto agents = discover_live_agents(**participant, arguments.dds.timeout(), [&](const auto& records) {
      const auto known = states->states();
      const auto live = live_logical_vehicles(records);
      return std::all_of(live.begin(), live.end(), [&](const std::string& v) { return known.count(v) > 0; });
    });
    if (!agents) {
      std::cerr << "error: " << agents.error().message << "\n";
      return kExitFailure;
    }
    const auto live = live_logical_vehicles(*agents);
    if (live.empty()) {
      std::cerr << "error: no logical agent answered on domain " << arguments.dds.domain_id << " within "
                << arguments.dds.timeout_seconds << " s\n";
      return kExitNoAnswer;
    }
    asked = vehicles_to_ask(arguments, pause, live, states->states(), standing, unknown_state);
  }
  auto client = PauseClient::create(**participant, logical_agent::kServiceArea, logical_agent::kPauseService);
  if (!client) {
    std::cerr << "error: " << client.error().message << "\n";
    return kExitFailure;
  }
  int failure = kExitOk;
  auto waited = ask_all(**client, arguments, pause, asked, failure);
  if (pause && arguments.wait_seconds > 0) {
    waited.insert(waited.end(), standing.begin(), standing.end());
    std::sort(waited.begin(), waited.end());
    states->wait(
        [&](const VehicleStates::States& known) {
          return std::all_of(waited.begin(), waited.end(), [&](const std::string& v) { return standing_paused(known, v); });
        },
        std::chrono::milliseconds(static_cast<std::int64_t>(arguments.wait_seconds * 1000)));
    const auto known = states->states();
    for (const auto& vehicle : waited) {
      if (standing_paused(known, vehicle)) {
        std::cout << "vehicle '" << vehicle << "' stands paused\n";
      } else {
        std::cerr << "error: vehicle '" << vehicle << "' not standing paused within " << arguments.wait_seconds
                  << " s\n";
        failure = kExitFailure;
      }
    }
  }
  return unknown_state ? kExitFailure : failure;
}

}  // namespace

void add_pause_command(CLI::App& app, CommandContext& context) {
  auto paused = std::make_shared<PauseArguments>();
  auto* pause = app.add_subcommand(
      "pause", "Pause a vehicle, or all: it stops at the next vertex it can and begins nothing new until resumed");
  pause->add_option("vehicle", paused->vehicle, "The vehicle id")->check(cli::identifier());
  pause->add_flag("--all", paused->all, "Every vehicle whose logical agent is alive (those paused already are left as they are)");
  pause->add_option("--reason", paused->reason, "Why (shown in droverctl vehicles)");
  pause->add_option("--wait", paused->wait_seconds,
                    "Also wait up to S seconds until the vehicles stand paused (exit 1 if one does not)")
      ->transform(cli::non_negative());
  add_dds_tool_options(*pause, paused->dds, 5.0);
  pause->callback([paused, &context] { context.exit_code = run_pause(*paused, true); });

  auto resumed = std::make_shared<PauseArguments>();
  auto* resume = app.add_subcommand("resume", "Resume a paused vehicle, or all");
  resume->add_option("vehicle", resumed->vehicle, "The vehicle id")->check(cli::identifier());
  resume->add_flag("--all", resumed->all, "Every paused vehicle whose logical agent is alive");
  resume->add_option("--reason", resumed->reason, "With --all: only the vehicles paused for this reason");
  add_dds_tool_options(*resume, resumed->dds, 5.0);
  resume->callback([resumed, &context] { context.exit_code = run_pause(*resumed, false); });
}

}  // namespace drover::cli
