// `drover load-generator --topology FILE [--station V ...] [--seed N] [--max-orders N] ...`:
// keeps idle vehicles busy with random orders between stations (docs/launch.md). It runs
// until SIGINT or SIGTERM (exit 0). Bad options or files: exit 2; DDS setup failures: exit 1.

#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "agents/cli/clock_options.hpp"
#include "agents/cli/command.hpp"
#include "drover/common/logging.hpp"
#include "drover/dds/heartbeat_publisher.hpp"
#include "drover/dds/shutdown_signal.hpp"
#include "drover/launcher/load_generator.hpp"
#include "drover/topology/topology_file.hpp"

namespace drover::cli {

namespace {

struct LoadGeneratorArguments {
  std::string topology_file;
  std::string agent_id = "load-generator";
  std::uint32_t domain_id = 0;
  std::string xml_profile;
  ClockArguments clock;
  std::string log_level = "info";
  launcher::LoadGeneratorOptions generator;
};

/// The stations orders go to: the ones named, which must be vertices, or every vertex of
/// kind station. \return them, or a message naming the bad one.
Result<std::vector<std::string>> stations_of(const topology::Topology& topology,
                                             const std::vector<std::string>& named,
                                             const std::string& file) {
  if (named.empty()) {
    std::vector<std::string> stations;
    for (const auto& vertex : topology.vertices()) {
      if (vertex.kind == topology::VertexKind::station) stations.push_back(vertex.id);
    }
    if (stations.size() < 2) {
      return fail(ErrorCode::invalid_argument, file + " has fewer than two stations: name them with --station");
    }
    return stations;
  }
  for (const auto& id : named) {
    const auto entity = topology.find(id);
    if (!entity || !topology.is_vertex(*entity)) {
      return fail(ErrorCode::invalid_argument, "--station: '" + id + "' is not a vertex of " + file);
    }
  }
  return named;
}

int run(LoadGeneratorArguments arguments) {
  make_agent_logger(arguments.agent_id, arguments.log_level);
  auto loaded = topology::load_topology_file(arguments.topology_file);
  if (!loaded) {
    return report_bad_file(arguments.topology_file, loaded.error());
  }
  auto stations = stations_of(*loaded, arguments.generator.stations, arguments.topology_file);
  if (!stations) {
    std::cerr << "error: " << stations.error().message << "\n";
    return kExitBadInput;
  }
  arguments.generator.stations = std::move(*stations);
  auto clock = make_clock(arguments.clock);
  if (!clock) {
    std::cerr << "error: " << clock.error().message << "\n";
    return kExitBadInput;
  }
  if (auto installed = dds::install_shutdown_handlers(); !installed) {
    std::cerr << "error: " << installed.error().message << "\n";
    return kExitFailure;
  }
  dds::ParticipantOptions participant_options;
  participant_options.domain_id = arguments.domain_id;
  participant_options.agent_id = arguments.agent_id;
  participant_options.xml_profile_file = arguments.xml_profile;
  auto participant = dds::Participant::create(participant_options);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  const auto station_count = arguments.generator.stations.size();
  auto generator = launcher::LoadGenerator::create(**participant, std::move(arguments.generator));
  if (!generator) {
    std::cerr << "error: " << generator.error().message << "\n";
    return generator.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  dds::HeartbeatOptions heartbeat_options;
  heartbeat_options.kind = "load-generator";
  auto heartbeat = dds::HeartbeatPublisher::create(**participant, *clock, heartbeat_options);
  if (!heartbeat) {
    std::cerr << "error: " << heartbeat.error().message << "\n";
    return kExitFailure;
  }
  spdlog::info("load generator '{}' sends orders between {} stations on domain {}", arguments.agent_id,
               station_count, arguments.domain_id);
  dds::wait_for_shutdown();
  const auto figures = (*generator)->figures();
  spdlog::info("load generator '{}' stopping: {} orders queued, {} refused, {} finished, {} failed, {} withdrawn; "
               "{} vehicle(s) left out",
               arguments.agent_id, figures.queued, figures.refused, figures.finished, figures.failed,
               figures.withdrawn, figures.left_out);
  heartbeat->reset();
  generator->reset();
  participant->reset();
  return kExitOk;
}

}  // namespace

void add_load_generator_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<LoadGeneratorArguments>();
  auto* command = app.add_subcommand(
      "load-generator", "Keep idle vehicles busy with random transport orders between stations "
                        "(load at one, unload at another) until SIGINT/SIGTERM");
  command->add_option("--topology", arguments->topology_file, "Topology file (.json or .map)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--station", arguments->generator.stations,
                      "A station orders may use (repeatable; default: every vertex of kind station)")
      ->check(identifier());
  command->add_option("--vehicle", arguments->generator.vehicles,
                      "A vehicle to serve (repeatable; default: every vehicle that reports its state)")
      ->check(identifier());
  command->add_option("--seed", arguments->generator.seed, "Random seed (default 1)")
      ->transform(whole_in(0, kLargestWholeOption));
  command->add_option("--max-orders", arguments->generator.max_orders,
                      "Stop sending after this many orders (default 0: never)")
      ->transform(whole_in(0, kLargestWholeOption));
  command->add_option("--id", arguments->agent_id, "Agent id; orders are named <id>-<n> (default load-generator)")
      ->check(identifier());
  command->add_option("--domain", arguments->domain_id, "DDS domain id")->transform(cli::whole_in(0, 232));
  command->add_option("--xml-profile", arguments->xml_profile, "Fast DDS XML profiles file")
      ->check(CLI::ExistingFile);
  add_clock_options(*command, arguments->clock);
  command->add_option("--log-level", arguments->log_level, "trace, debug, info, warn, error, off")
      ->check(cli::log_level());
  command->callback([arguments, &context] { context.exit_code = run(*arguments); });
}

}  // namespace drover::cli
