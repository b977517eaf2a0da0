#pragma once
// A launch file (launch/*.json, docs/launch.md): one deployment's domain id, shared clock,
// topology file and the agents to start. Parsing checks everything that can be checked
// before a process starts (kinds, fields, vertices, partitions, profiles, ids), so that a
// bad file starts nothing.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/topology/topology_builder.hpp"

namespace drover::launcher {

/// The kinds of agents a launch file may start, in the order they are stopped last-first.
enum class AgentKind { topology, ran_sim, routing, logical, load_generator };

/// The launch file's name of a kind ("topology", "ran-sim", ...), which is also the
/// `drover` subcommand ("topology-agent", "ran-sim", ...) given by subcommand().
std::string_view kind_name(AgentKind kind) noexcept;
std::string_view subcommand(AgentKind kind) noexcept;

enum class RestartPolicy {
  never,       ///< an agent that ends stays ended
  on_failure,  ///< restarted when it ends with a non-zero code or a signal
};

/// One agent to start.
struct AgentEntry {
  AgentKind kind = AgentKind::topology;
  /// The agent id: its DDS participant name and the prefix of its output lines.
  std::string id;
  /// The vehicle of a ran-sim or logical agent; empty for other kinds.
  std::string vehicle;
  RestartPolicy restart = RestartPolicy::never;
  /// How many times it is restarted at most (on_failure).
  int max_restarts = 5;
  /// The subcommand's options: its identity (agent id, vehicle id), the topology file when
  /// the kind takes one, then the entry's fields and its vehicle profile. The launcher
  /// adds the domain id and the clock.
  std::vector<std::string> options;
  /// Files to write before anything starts (path, content): a logical agent's vehicle
  /// profile, made from the launch file's profile, lives in the state directory.
  std::vector<std::pair<std::filesystem::path, std::string>> files;
  /// The journals it opens (`db`): their directories are made before anything starts.
  std::vector<std::filesystem::path> journals;
};

/// A parsed and checked launch file.
struct LaunchFile {
  std::filesystem::path path;
  std::string name;
  std::uint32_t domain_id = 0;
  double time_factor = 1.0;
  /// Shared-clock time when the launch starts; nullopt: the Unix time then ("now").
  std::optional<TimeNs> epoch_ns;
  /// The topology file, absolute.
  std::filesystem::path topology_file;
  /// In start order (the file's order).
  std::vector<AgentEntry> agents;
};

/// One problem of a launch file: `where` names the field (e.g. "agents[3].at"), `what`
/// says what is wrong with it.
using LaunchProblem = topology::Diagnostic;
using LaunchProblems = topology::Diagnostics;

/// Reads and checks a launch file. Relative paths in it are relative to its directory;
/// relative journal paths (`db`) are relative to `state_dir`.
/// \return the launch file, or every problem found (nothing may be started then); a
///         file that is not one strict JSON document (malformed, a NUL byte, keys given
///         twice: parse_json_document) is refused with those problems alone.
Result<LaunchFile, LaunchProblems> load_launch_file(const std::filesystem::path& path,
                                                    const std::filesystem::path& state_dir);

/// As load_launch_file, from JSON text; `path` names the file in messages and anchors
/// relative paths.
Result<LaunchFile, LaunchProblems> parse_launch_file(std::string_view text,
                                                     const std::filesystem::path& path,
                                                     const std::filesystem::path& state_dir);

/// Makes what the agents of `file` need on disk before any of them starts, so that none
/// fails at its start after others started: the directories of their journals, and their
/// files (AgentEntry::files). \return success, or io naming the path and the agent.
Status prepare_state(const LaunchFile& file);

}  // namespace drover::launcher
