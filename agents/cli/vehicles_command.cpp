// `droverctl vehicles [--domain N] [--timeout S] [--json]`: what every vehicle of a domain
// is doing, from the state its logical agent publishes (drover/logical/vehicle, kept for
// late joiners): activity, vertex, order, queue, motion, battery. Exit 3 when no logical
// agent answers within the timeout.

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "agents/cli/json_line.hpp"
#include "agents/cli/agent_discovery.hpp"
#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "agents/cli/table.hpp"
#include "agents/cli/vehicle_states.hpp"
#include "drover/dds/agent_directory.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/logical_agent/wire_names.hpp"

namespace drover::cli {
namespace {

struct VehiclesArguments {
  DdsToolOptions dds;
  bool json = false;
};

/// The vehicles of live logical agents whose state has not arrived.
std::vector<std::string> vehicles_unseen(const std::vector<dds::AgentRecord>& agents,
                                         const VehicleStates::States& states) {
  std::vector<std::string> unseen;
  for (const auto& vehicle : live_logical_vehicles(agents)) {
    if (states.count(vehicle) == 0) unseen.push_back(vehicle);
  }
  return unseen;
}

std::string battery_text(double state_of_charge) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(0) << state_of_charge * 100 << " %";
  return out.str();
}

/// The state column: the activity, or "pausing" while a paused vehicle still drives its
/// last moves.
std::string state_text(const msg::VehicleState& state) {
  const bool driving = state.state() == msg::VEHICLE_DRIVING || state.state() == msg::VEHICLE_PARKING ||
                       state.state() == msg::VEHICLE_CHARGING;
  if (state.paused() && driving && state.moving()) return "pausing";
  return std::string(logical_agent::activity_name(state.state()));
}

/// The paused column: "-", or the pause's reason ("yes" without one).
std::string paused_text(const msg::VehicleState& state) {
  if (!state.paused()) return "-";
  return state.pause_reason().empty() ? "yes" : state.pause_reason();
}

void print_vehicles(const VehicleStates::States& states) {
  std::vector<std::vector<std::string>> rows;
  for (const auto& [vehicle, state] : states) {
    rows.push_back({vehicle, state_text(state), state.vertex().empty() ? "-" : state.vertex(),
                    state.order().empty() ? "-" : state.order(), std::to_string(state.queued_orders()),
                    state.moving() ? "yes" : "no", battery_text(state.state_of_charge()), paused_text(state)});
  }
  print_table(std::cout, {"VEHICLE", "STATE", "VERTEX", "ORDER", "QUEUED", "MOVING", "BATTERY", "PAUSED"}, rows);
}

void print_json(const VehicleStates::States& states) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [vehicle, state] : states) {
    out.push_back({{"vehicle", vehicle},
                   {"ran", state.ran()},
                   {"state", std::string(logical_agent::activity_name(state.state()))},
                   {"vertex", state.vertex()},
                   {"order", state.order()},
                   {"queued_orders", state.queued_orders()},
                   {"moving", state.moving()},
                   {"state_of_charge", state.state_of_charge()},
                   {"paused", state.paused()},
                   {"pause_reason", state.pause_reason()},
                   {"time_ns", state.time().ns()}});
  }
  std::cout << json_line(out) << "\n";
}

int run_vehicles(const VehiclesArguments& arguments) {
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  auto collected = VehicleStates::create(**participant);
  if (!collected) {
    std::cerr << "error: " << collected.error().message << "\n";
    return kExitFailure;
  }
  // Every logical agent present is discovered as `droverctl agents` does it, and has shown
  // its vehicle's state; never past the timeout.
  const auto agents = discover_live_agents(**participant, arguments.dds.timeout(), [&](const auto& records) {
    const auto states = (*collected)->states();
    return !states.empty() && vehicles_unseen(records, states).empty();
  });
  if (!agents) {
    std::cerr << "error: " << agents.error().message << "\n";
    return kExitFailure;
  }
  const auto states = (*collected)->states();
  collected->reset();
  const auto missing = vehicles_unseen(*agents, states);
  if (!missing.empty() && !states.empty()) {
    std::cerr << "warning: no state from the logical agent of";
    for (const auto& vehicle : missing) std::cerr << " '" << vehicle << "'";
    std::cerr << " within " << arguments.dds.timeout_seconds << " s: not listed\n";
  }
  if (states.empty()) {
    std::cerr << "error: no logical agent answered on domain " << arguments.dds.domain_id << " within "
              << arguments.dds.timeout_seconds << " s\n";
    return kExitNoAnswer;
  }
  if (arguments.json) {
    print_json(states);
  } else {
    print_vehicles(states);
  }
  return kExitOk;
}

}  // namespace

void add_vehicles_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<VehiclesArguments>();
  auto* command = app.add_subcommand(
      "vehicles", "What every vehicle is doing: activity, vertex, order, queue, motion, battery (from its logical agent)");
  add_dds_tool_options(*command, arguments->dds, 2.0);
  command->add_flag("--json", arguments->json, "Print a JSON array instead of a table");
  command->callback([arguments, &context] { context.exit_code = run_vehicles(*arguments); });
}

}  // namespace drover::cli
