// `drover`: the one executable of Drover; every agent and tool is a subcommand.

#include <CLI/CLI.hpp>

#include "agents/cli/command.hpp"
#include "bench/bench_command.hpp"

int main(int argc, char** argv) {
  using namespace drover::cli;
  CLI::App app{"Drover: a decentralized fleet planner for AGVs, mobile robots and people.",
               "drover"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "drover 0.1.0");

  CommandContext context;
  add_topology_commands(app, context);
  add_topology_agent_command(app, context);
  add_routing_agent_command(app, context);
  add_ran_commands(app, context);
  add_logical_agent_command(app, context);
  add_launch_command(app, context);
  add_load_generator_command(app, context);
  drover::bench::add_bench_commands(app, context);

  return run_app(app, context, argc, argv);
}
