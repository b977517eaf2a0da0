// `drover logical-agent --id V1 --topology FILE [options]`: the logical agent of one vehicle
// (docs/logical-agent.md) until SIGINT or SIGTERM (exit 0; its future reservations are
// cancelled). Bad options or files (an order journal damaged or another vehicle's
// included): exit 2; DDS setup failures, an order journal that cannot be opened: exit 1.

#include <iostream>
#include <memory>
#include <string>

#include "agents/cli/clock_options.hpp"
#include "agents/cli/command.hpp"
#include "agents/logical_agent/src/logical_agent.hpp"
#include "drover/carp/vehicle_profile_json.hpp"
#include "drover/common/logging.hpp"
#include "drover/dds/shutdown_signal.hpp"
#include "drover/logical_agent/charging.hpp"
#include "drover/topology/topology_file.hpp"

namespace drover::cli {

namespace {

struct LogicalAgentArguments {
  std::string vehicle_id;
  std::string topology_file;
  std::string vehicle_file;
  std::string ran_agent;
  std::uint32_t domain_id = 0;
  std::string xml_profile;
  std::string order_journal;
  ClockArguments clock;
  std::string log_level = "info";
  std::size_t lookahead = 2;
  double delay_threshold = 2;
  double park_after = 30;
  double charge_below = logical_agent::kDefaultChargeBelow;
  double charge_to = logical_agent::kDefaultChargeTo;
  double error_limit = 60;
  double route_limit = 120;
  double wait_alarm = 60;
};

int fail_input(const std::string& message) {
  std::cerr << "error: " << message << "\n";
  return kExitBadInput;
}

int run(const LogicalAgentArguments& arguments) {
  if (auto problem = logical_agent::charging_problem(arguments.charge_below, arguments.charge_to)) {
    return fail_input("--charge-to: " + *problem);
  }
  make_agent_logger(arguments.vehicle_id, arguments.log_level);
  auto loaded = topology::load_topology_file(arguments.topology_file);
  if (!loaded) {
    return report_bad_file(arguments.topology_file, loaded.error());
  }
  logical_agent::LogicalAgentOptions options;
  if (!arguments.vehicle_file.empty()) {
    auto vehicle = carp::read_vehicle_profile(arguments.vehicle_file);
    if (!vehicle) return fail_input("--vehicle: " + vehicle.error().message);
    options.vehicle = *vehicle;
  }
  if (options.vehicle.id.empty()) options.vehicle.id = arguments.vehicle_id;
  options.participant.agent_id = arguments.vehicle_id;
  options.participant.domain_id = arguments.domain_id;
  options.participant.xml_profile_file = arguments.xml_profile;
  options.ran_agent = arguments.ran_agent;
  options.lookahead = arguments.lookahead;
  options.delay_threshold = seconds_to_ns(arguments.delay_threshold);
  options.park_after = arguments.park_after < 0 ? -1 : seconds_to_ns(arguments.park_after);
  options.charge_below = arguments.charge_below;
  options.charge_to = arguments.charge_to;
  options.error_limit = seconds_to_ns(arguments.error_limit);
  options.route_limit = seconds_to_ns(arguments.route_limit);
  options.wait_alarm = seconds_to_ns(arguments.wait_alarm);
  options.order_journal = arguments.order_journal;

  auto clock = make_clock(arguments.clock);
  if (!clock) return fail_input(clock.error().message);
  if (auto installed = dds::install_shutdown_handlers(); !installed) {
    std::cerr << "error: " << installed.error().message << "\n";
    return kExitFailure;
  }
  auto world = std::make_shared<const topology::Topology>(std::move(*loaded));
  auto agent = logical_agent::LogicalAgent::create(world, *clock, options);
  if (!agent) {
    std::cerr << "error: " << agent.error().message << "\n";
    const ErrorCode code = agent.error().code;
    const bool bad_input =
        code == ErrorCode::invalid_argument || code == ErrorCode::parse || code == ErrorCode::conflict;
    return bad_input ? kExitBadInput : kExitFailure;
  }
  spdlog::info("logical agent of vehicle '{}' on '{}', domain {}, time factor {}", arguments.vehicle_id,
               world->name(), arguments.domain_id, clock->factor());
  dds::wait_for_shutdown();
  spdlog::info("logical agent '{}' shutting down", arguments.vehicle_id);
  agent->reset();
  return kExitOk;
}

}  // namespace

void add_logical_agent_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<LogicalAgentArguments>();
  auto* command = app.add_subcommand(
      "logical-agent",
      "Run the logical agent of one vehicle until SIGINT/SIGTERM: it takes orders on "
      "drover/logical/order, drives its RAN (ran-<id>) along reserved routes and publishes order "
      "progress, vehicle state and operator alarms");
  command->add_option("--id", arguments->vehicle_id, "The vehicle id (also the agent id)")
      ->required()
      ->check(cli::identifier());
  command->add_option("--topology", arguments->topology_file, "Topology file (.json or .map)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--vehicle", arguments->vehicle_file,
                      "Vehicle profile JSON (max_speed, acceleration, deceleration, length, width, ...)")
      ->check(CLI::ExistingFile);
  command->add_option("--ran-id", arguments->ran_agent, "The RAN's agent id (default: ran-<id>)")
      ->check(cli::identifier());
  command->add_option("--domain", arguments->domain_id, "DDS domain id")->transform(cli::whole_in(0, 232));
  command->add_option("--xml-profile", arguments->xml_profile, "Fast DDS XML profiles file")
      ->check(CLI::ExistingFile);
  command->add_option("--db", arguments->order_journal,
                      "Order journal (SQLite; created if absent): orders survive a restart of the agent")
      ->check(cli::non_empty());
  add_clock_options(*command, arguments->clock);
  command->add_option("--lookahead", arguments->lookahead, "Vertices allocated ahead of the vehicle (default 2)")
      ->transform(cli::whole_in(1, 1000));
  command->add_option("--delay-threshold", arguments->delay_threshold,
                      "s of lateness at the next vertex before a delay is propagated (default 2)")
      ->transform(cli::positive());
  command->add_option("--park-after", arguments->park_after,
                      "s idle before driving to a parking vertex; negative: never (default 30)")
      ->transform(cli::number_in(-cli::kLargestOptionValue, cli::kLargestOptionValue));
  command->add_option("--charge-below", arguments->charge_below,
                      "State of charge under which it charges before new work; 0: never (default 0.2)")
      ->transform(cli::number_in(0.0, 1.0));
  command->add_option("--charge-to", arguments->charge_to, "State of charge a charge aims at, > 0 (default 0.9)")
      ->transform(cli::positive_at_most(1.0));
  command->add_option("--error-limit", arguments->error_limit,
                      "s a recoverable RAN error may last before the order fails (default 60)")
      ->transform(cli::positive());
  command->add_option("--route-limit", arguments->route_limit,
                      "s to keep asking for a route the timelines or locks refuse (default 120)")
      ->transform(cli::non_negative());
  command->add_option("--wait-alarm", arguments->wait_alarm,
                      "s waiting for one allocation before the operator is warned; 0: never (default 60)")
      ->transform(cli::non_negative());
  command->add_option("--log-level", arguments->log_level, "trace, debug, info, warn, error, off")
      ->check(cli::log_level());
  command->callback([arguments, &context] { context.exit_code = run(*arguments); });
}

}  // namespace drover::cli
