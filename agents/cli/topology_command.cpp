#include "agents/cli/command.hpp"

namespace drover::cli {

void add_topology_commands(CLI::App& app, CommandContext& context) {
  auto* topology = app.add_subcommand("topology", "Work with topology files");
  topology->require_subcommand(1);
  (void)context;
}

}  // namespace drover::cli
