// `drover ran-sim --id V1 --topology FILE --at VERTEX [options]`: one simulated vehicle as
// its own RAN process. It serves drover/ran/command and drover/ran/sim_fault, publishes
// its status on drover/ran/status every status period and on every change, and beats its
// heartbeat, until SIGINT or SIGTERM (exit 0). Bad options or files: exit 2; DDS setup
// failures: exit 1.

#include <chrono>
#include <cmath>
#include <exception>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "agents/cli/clock_options.hpp"
#include "agents/cli/command.hpp"
#include "drover/common/clock.hpp"
#include "drover/common/logging.hpp"
#include "drover/dds/shutdown_signal.hpp"
#include "drover/ran/sim_driver.hpp"
#include "drover/ran_runner/runner.hpp"
#include "drover/ran_runner/sim_fault_server.hpp"
#include "drover/topology/topology_file.hpp"

namespace drover::cli {

namespace {

struct RanSimArguments {
  std::string vehicle_id;
  std::string topology_file;
  std::string at_vertex;
  std::optional<double> heading;
  std::uint32_t domain_id = 0;
  std::string agent_id;
  std::string xml_profile;
  ClockArguments clock;
  int status_period_ms = 100;
  std::string log_level = "info";
  ran::SimVehicleConfig vehicle;
  double load_seconds = 5;
  double unload_seconds = 5;
  std::vector<std::string> custom_actions;  // NAME=SECONDS
  bool loaded = false;
};

int fail_input(const std::string& message) {
  std::cerr << "error: " << message << "\n";
  return kExitBadInput;
}

int run(RanSimArguments arguments) {
  make_agent_logger(arguments.agent_id.empty() ? ran::ran_agent_id(arguments.vehicle_id)
                                               : arguments.agent_id,
                    arguments.log_level);
  auto loaded = topology::load_topology_file(arguments.topology_file);
  if (!loaded) {
    return report_bad_file(arguments.topology_file, loaded.error());
  }
  auto world = std::make_shared<const topology::Topology>(std::move(*loaded));
  const auto at = world->find(arguments.at_vertex);
  if (!at || !world->is_vertex(*at)) {
    return fail_input("--at: '" + arguments.at_vertex + "' is not a vertex of " +
                      arguments.topology_file);
  }
  const auto& vertex = world->vertex(*at);
  const ran::Pose start{vertex.position.x(), vertex.position.y(),
                        arguments.heading.value_or(vertex.orientation.value_or(0.0))};

  auto& config = arguments.vehicle;
  config.vehicle_id = arguments.vehicle_id;
  config.load_duration = seconds_to_ns(arguments.load_seconds);
  config.unload_duration = seconds_to_ns(arguments.unload_seconds);
  config.initial_load = arguments.loaded ? ran::LoadState::loaded : ran::LoadState::empty;
  for (const auto& entry : arguments.custom_actions) {
    const auto equals = entry.find('=');
    const double seconds = equals == std::string::npos
                               ? -1
                               : cli::parse_decimal(std::string_view(entry).substr(equals + 1)).value_or(-1);
    if (equals == 0 || seconds < 0 || seconds > cli::kLargestOptionValue) {
      return fail_input("--custom-action '" + entry + "': expected NAME=SECONDS, SECONDS from 0 to 1e9");
    }
    config.custom_actions[entry.substr(0, equals)] = seconds_to_ns(seconds);
  }

  auto clock = make_clock(arguments.clock);
  if (!clock) return fail_input(clock.error().message);

  auto vehicle = ran::SimVehicle::create(config, start, clock->now(), world);
  if (!vehicle) return fail_input(vehicle.error().message);
  ran::SimDriver driver(std::move(*vehicle));

  if (auto installed = dds::install_shutdown_handlers(); !installed) {
    std::cerr << "error: " << installed.error().message << "\n";
    return kExitFailure;
  }
  ran::RanNodeOptions options;
  options.vehicle_id = arguments.vehicle_id;
  options.agent_id = arguments.agent_id;
  options.domain_id = arguments.domain_id;
  options.xml_profile_file = arguments.xml_profile;
  options.status_period = std::chrono::milliseconds(arguments.status_period_ms);
  auto node = ran::RanNode::create(driver, options, *clock);
  if (!node) {
    std::cerr << "error: " << node.error().message << "\n";
    return node.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  auto faults = ran::SimFaultServer::create((*node)->participant(), (*node)->runner(), driver);
  if (!faults) {
    std::cerr << "error: " << faults.error().message << "\n";
    return kExitFailure;
  }
  spdlog::info("simulated vehicle '{}' at '{}' ({:.2f}, {:.2f}) on domain {}, time factor {}",
               arguments.vehicle_id, arguments.at_vertex, start.x, start.y, arguments.domain_id,
               clock->factor());
  dds::wait_for_shutdown();
  spdlog::info("simulated vehicle '{}' shutting down", arguments.vehicle_id);
  faults->reset();
  node->reset();
  return kExitOk;
}

}  // namespace

void add_ran_commands(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<RanSimArguments>();
  auto* sim = app.add_subcommand(
      "ran-sim",
      "Run one simulated vehicle as a robot agent node (RAN) until SIGINT/SIGTERM: it executes "
      "moves and actions from drover/ran/command and publishes its status on drover/ran/status");
  sim->add_option("--id", arguments->vehicle_id, "The vehicle id")->required()->check(cli::identifier());
  sim->add_option("--topology", arguments->topology_file, "Topology file (.json or .map)")
      ->required()
      ->check(CLI::ExistingFile);
  sim->add_option("--at", arguments->at_vertex, "The vertex the vehicle starts at")->required();
  sim->add_option("--heading", arguments->heading,
                  "Start heading in radians (default: the vertex orientation, else 0)")
      ->transform(cli::number_in(-1000, 1000));
  sim->add_option("--domain", arguments->domain_id, "DDS domain id")->transform(cli::whole_in(0, 232));
  sim->add_option("--agent-id", arguments->agent_id, "Agent id (default: ran-<id>)")->check(cli::identifier());
  sim->add_option("--xml-profile", arguments->xml_profile, "Fast DDS XML profiles file")
      ->check(CLI::ExistingFile);
  add_clock_options(*sim, arguments->clock);
  sim->add_option("--status-period-ms", arguments->status_period_ms,
                  "Real milliseconds between status reports (default 100)")
      ->transform(cli::whole_in(1, 60000));
  sim->add_option("--log-level", arguments->log_level, "trace, debug, info, warn, error, off")
      ->check(cli::log_level());
  auto& vehicle = arguments->vehicle;
  sim->add_option("--max-speed", vehicle.max_speed, "m/s (default 1)")->transform(cli::positive());
  sim->add_option("--acceleration", vehicle.acceleration, "m/s^2 (default 0.5)")->transform(cli::positive());
  sim->add_option("--deceleration", vehicle.deceleration, "m/s^2 (default 0.5)")->transform(cli::positive());
  sim->add_option("--angular-speed", vehicle.angular_speed, "rad/s turning on the spot (default 1)")->transform(cli::positive());
  sim->add_option("--battery-capacity", vehicle.battery_capacity_wh, "Wh (default 1000)")->transform(cli::positive());
  auto* battery = sim->add_option("--battery", vehicle.battery_initial_wh, "Wh at start (default: full, the capacity)")
                      ->transform(cli::non_negative());
  sim->add_option("--drain", vehicle.drain_wh_per_metre, "Wh per metre driven (default 0.5)")->transform(cli::non_negative());
  sim->add_option("--charge-rate", vehicle.charge_wh_per_second, "Wh per second charging (default 1)")->transform(cli::non_negative());
  sim->add_option("--load-duration", arguments->load_seconds, "s (default 5)")
      ->transform(cli::non_negative());
  sim->add_option("--unload-duration", arguments->unload_seconds, "s (default 5)")
      ->transform(cli::non_negative());
  sim->add_option("--custom-action", arguments->custom_actions,
                  "A custom action the vehicle supports: NAME=SECONDS (repeatable)");
  sim->add_flag("--loaded", arguments->loaded, "Start loaded");
  sim->callback([arguments, battery, &context] {
    if (battery->count() == 0) arguments->vehicle.battery_initial_wh = arguments->vehicle.battery_capacity_wh;
    context.exit_code = run(*arguments);
  });
}

}  // namespace drover::cli
