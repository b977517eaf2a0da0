#pragma once
// Every agent and tool is a subcommand of the one `drover` executable. Each subcommand
// registers itself on the CLI11 app and reports its exit code through CommandContext.

#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "agents/cli/number_checks.hpp"
#include "agents/cli/text_checks.hpp"
#include "drover/topology/topology_builder.hpp"

namespace drover::cli {

/// Exit codes shared by every Drover tool.
enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,     ///< the operation ran and failed
  kExitBadInput = 2,    ///< bad usage or invalid input
  kExitNoAnswer = 3,    ///< no agent answered
};

/// Prints every problem found in `file` as "error: FILE:WHERE: WHAT" on standard error.
/// \return kExitBadInput, the exit code of a tool whose input file was refused.
inline int report_bad_file(const std::string& file, const topology::Diagnostics& problems) {
  for (const auto& problem : problems) {
    std::cerr << "error: " << topology::diagnostic_text(file, problem) << "\n";
  }
  return kExitBadInput;
}

/// Filled in by the subcommand that ran.
struct CommandContext {
  int exit_code = kExitOk;
};

/// Parses the command line into `app` and runs the chosen subcommand. Help and version
/// requests print and exit 0; a parse error prints CLI11's message and gives kExitBadInput;
/// an exception escaping a command (commands report expected failures themselves) prints
/// "error: internal: ..." and gives kExitFailure. Output that could not be written to
/// standard output prints "error: cannot write to standard output" and fails the run
/// (kExitFailure, unless the command had failed already). \return the exit code.
int run_app(CLI::App& app, const CommandContext& context, int argc, char** argv);

/// `drover topology ...` (validate and friends).
void add_topology_commands(CLI::App& app, CommandContext& context);

/// `drover topology-agent`: a topology agent process (agents/topology_agent/).
void add_topology_agent_command(CLI::App& app, CommandContext& context);

/// `drover routing-agent`: a routing agent process (agents/routing_agent/).
void add_routing_agent_command(CLI::App& app, CommandContext& context);

/// `drover logical-agent`: the logical agent of one vehicle (agents/logical_agent/).
void add_logical_agent_command(CLI::App& app, CommandContext& context);

/// `drover ran-sim ...`: a simulated vehicle as a RAN process (agents/ran_runner/cli/).
void add_ran_commands(CLI::App& app, CommandContext& context);

/// `drover launch FILE`: starts and supervises the agents of a launch file (agents/launcher/).
void add_launch_command(CLI::App& app, CommandContext& context);

/// `drover load-generator`: random orders between stations to idle vehicles (agents/launcher/).
void add_load_generator_command(CLI::App& app, CommandContext& context);

}  // namespace drover::cli
