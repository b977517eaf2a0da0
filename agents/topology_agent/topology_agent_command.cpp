// `drover topology-agent --topology FILE [--partition NAME] [--db FILE] [--domain N] [--id ID]`: a
// topology agent process (docs/topology-agent.md). It serves until SIGINT or SIGTERM
// (exit 0). Bad options or files: exit 2; DDS setup failures: exit 1.

#include <iostream>
#include <optional>
#include <string>

#include "agents/cli/clock_options.hpp"
#include "agents/cli/command.hpp"
#include "agents/topology_agent/topology_agent.hpp"
#include "drover/common/clock.hpp"
#include "drover/common/logging.hpp"
#include "drover/dds/shutdown_signal.hpp"
#include "drover/topology/topology_file.hpp"

namespace drover::cli {

namespace {

struct TopologyAgentArguments {
  std::string topology_file;
  std::string partition;
  std::string journal_file;
  std::uint32_t domain_id = 0;
  std::string agent_id;
  std::string xml_profile;
  ClockArguments clock;
  std::string log_level = "info";
  bool drop_commit_replies = false;
  double departed_after = 10;
};

int run(const TopologyAgentArguments& arguments) {
  const std::string agent_id = !arguments.agent_id.empty() ? arguments.agent_id
                               : arguments.partition.empty() ? std::string("topology")
                                                             : "topology-" + arguments.partition;
  make_agent_logger(agent_id, arguments.log_level);
  auto loaded = topology::load_topology_file(arguments.topology_file);
  if (!loaded) {
    return report_bad_file(arguments.topology_file, loaded.error());
  }
  auto clock = make_clock(arguments.clock);
  if (!clock) {
    std::cerr << "error: " << clock.error().message << "\n";
    return kExitBadInput;
  }
  if (auto installed = dds::install_shutdown_handlers(); !installed) {
    std::cerr << "error: " << installed.error().message << "\n";
    return kExitFailure;
  }
  topology_agent::TopologyAgentOptions options;
  options.partition = arguments.partition;
  options.journal_file = arguments.journal_file;
  options.drop_commit_replies = arguments.drop_commit_replies;
  options.departed_after = std::chrono::milliseconds(static_cast<std::int64_t>(arguments.departed_after * 1000));
  options.participant.domain_id = arguments.domain_id;
  options.participant.agent_id = agent_id;
  options.participant.xml_profile_file = arguments.xml_profile;
  auto agent = topology_agent::TopologyAgent::create(std::move(*loaded), *clock, std::move(options));
  if (!agent) {
    std::cerr << "error: " << agent.error().message << "\n";
    const auto code = agent.error().code;
    return code == ErrorCode::invalid_argument || code == ErrorCode::parse || code == ErrorCode::conflict
               ? kExitBadInput
               : kExitFailure;
  }
  spdlog::info("topology agent '{}' serves {} entities of '{}' on domain {}", agent_id,
               (*agent)->owned_count(), arguments.topology_file, arguments.domain_id);
  dds::wait_for_shutdown();
  spdlog::info("topology agent '{}' shutting down", agent_id);
  agent->reset();
  return kExitOk;
}

}  // namespace

void add_topology_agent_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<TopologyAgentArguments>();
  auto* command = app.add_subcommand(
      "topology-agent", "Serve a topology (or one partition of it): entity descriptions, timelines, "
                        "reservations, allocations, locks, delays, over DDS");
  command->add_option("--topology", arguments->topology_file, "Topology file (.json or .map)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--partition", arguments->partition,
                      "Serve only the entities of this partition (default: all)")
      ->check(cli::identifier());
  command->add_option("--db", arguments->journal_file,
                      "SQLite journal: restored on start, written after every change (default: none)")
      ->check(cli::non_empty());
  command->add_option("--domain", arguments->domain_id, "DDS domain id")->transform(cli::whole_in(0, 232));
  command->add_option("--id", arguments->agent_id,
                      "Agent id (default: topology-<partition>, or topology)")
      ->check(cli::identifier());
  command->add_option("--xml-profile", arguments->xml_profile, "Fast DDS XML profiles file")
      ->check(CLI::ExistingFile);
  command->add_option("--departed-after", arguments->departed_after,
                      "s without a heartbeat before a logical agent's reservations here go, but for what "
                      "its vehicle occupies; 0: never (default 10)")
      ->transform(cli::non_negative());
  add_clock_options(*command, arguments->clock);
  command->add_option("--log-level", arguments->log_level, "trace, debug, info, warn, error, off")
      ->check(cli::log_level());
  command->add_flag("--drop-commit-replies", arguments->drop_commit_replies,
                    "TEST HOOK: apply commits but never answer them (a reply lost on the way)");
  command->callback([arguments, &context] { context.exit_code = run(*arguments); });
}

}  // namespace drover::cli
