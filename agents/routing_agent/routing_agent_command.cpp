// `drover routing-agent [--id ID] [--domain N] [--xml-profile FILE] ...`: a routing agent
// process (docs/routing-agent.md). It serves until SIGINT or SIGTERM (exit 0). Bad options:
// exit 2; DDS setup failures: exit 1.

#include <iostream>
#include <optional>
#include <string>

#include "agents/cli/clock_options.hpp"
#include "agents/cli/command.hpp"
#include "agents/routing_agent/routing_agent.hpp"
#include "drover/common/clock.hpp"
#include "drover/common/logging.hpp"
#include "drover/dds/shutdown_signal.hpp"

namespace drover::cli {

namespace {

struct RoutingAgentArguments {
  std::string agent_id = "routing";
  std::uint32_t domain_id = 0;
  std::string xml_profile;
  ClockArguments clock;
  double prepare_ttl_seconds = 5.0;
  int max_attempts = 5;
  double learn_timeout_seconds = 3.0;
  double horizon_seconds = 3600.0;
  bool hold_after_prepare = false;
  std::string log_level = "info";
};

std::chrono::milliseconds to_milliseconds(double seconds) {
  return std::chrono::milliseconds(static_cast<std::int64_t>(seconds * 1000.0));
}

int run(const RoutingAgentArguments& arguments) {
  make_agent_logger(arguments.agent_id, arguments.log_level);
  auto clock = make_clock(arguments.clock);
  if (!clock) {
    std::cerr << "error: " << clock.error().message << "\n";
    return kExitBadInput;
  }
  if (auto installed = dds::install_shutdown_handlers(); !installed) {
    std::cerr << "error: " << installed.error().message << "\n";
    return kExitFailure;
  }
  routing_agent::RoutingAgentOptions options;
  options.participant.domain_id = arguments.domain_id;
  options.participant.agent_id = arguments.agent_id;
  options.participant.xml_profile_file = arguments.xml_profile;
  options.planner.horizon = seconds_to_ns(arguments.horizon_seconds);
  options.prepare_ttl = seconds_to_ns(arguments.prepare_ttl_seconds);
  options.max_attempts = arguments.max_attempts;
  options.learn_timeout = to_milliseconds(arguments.learn_timeout_seconds);
  options.hold_after_prepare = arguments.hold_after_prepare;
  auto agent = routing_agent::RoutingAgent::create(*clock, std::move(options));
  if (!agent) {
    std::cerr << "error: " << agent.error().message << "\n";
    return agent.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  spdlog::info("routing agent '{}' serves routes on domain {}{}", arguments.agent_id, arguments.domain_id,
               arguments.hold_after_prepare ? " (TEST HOOK --hold-after-prepare: real routes are never committed)"
                                            : "");
  dds::wait_for_shutdown();
  spdlog::info("routing agent '{}' shutting down", arguments.agent_id);
  agent->reset();
  return kExitOk;
}

}  // namespace

void add_routing_agent_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<RoutingAgentArguments>();
  auto* command = app.add_subcommand(
      "routing-agent", "Serve routes (test and real) planned with CARP, reserved through the topology agents");
  command->add_option("--id", arguments->agent_id, "Agent id (default: routing)")->check(cli::identifier());
  command->add_option("--domain", arguments->domain_id, "DDS domain id")->transform(cli::whole_in(0, 232));
  command->add_option("--xml-profile", arguments->xml_profile, "Fast DDS XML profiles file")
      ->check(CLI::ExistingFile);
  add_clock_options(*command, arguments->clock);
  command->add_option("--prepare-ttl", arguments->prepare_ttl_seconds,
                      "Shared-clock seconds a prepared hold lives before it expires, at most 3600 (default 5)")
      ->transform(cli::positive_at_most(3600));
  command->add_option("--max-attempts", arguments->max_attempts,
                      "Plan/prepare rounds of a real route before ERROR_CONFLICT (default 5)")
      ->transform(cli::whole_in(1, 100));
  command->add_option("--learn-timeout", arguments->learn_timeout_seconds,
                      "Seconds a request waits for the descriptions it needs (default 3)")
      ->transform(cli::positive());
  command->add_option("--horizon", arguments->horizon_seconds,
                      "Planning horizon after the start time, seconds (default 3600)")
      ->transform(cli::positive());
  command->add_flag("--hold-after-prepare", arguments->hold_after_prepare,
                    "TEST HOOK: prepare real routes but never commit them (log a marker and wait)");
  command->add_option("--log-level", arguments->log_level, "trace, debug, info, warn, error, off")
      ->check(cli::log_level());
  command->callback([arguments, &context] { context.exit_code = run(*arguments); });
}

}  // namespace drover::cli
