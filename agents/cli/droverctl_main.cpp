// `droverctl`: the operator tool. Each command is a subcommand (agents_command.cpp, ...).

#include <CLI/CLI.hpp>

#include "agents/cli/droverctl_commands.hpp"

int main(int argc, char** argv) {
  using namespace drover::cli;
  CLI::App app{"droverctl: inspect and operate a running Drover fleet.", "droverctl"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "droverctl 0.1.0");

  CommandContext context;
  add_agents_command(app, context);
  add_lock_command(app, context);
  add_unlock_command(app, context);
  add_release_command(app, context);
  add_timeline_command(app, context);
  add_order_command(app, context);
  add_pause_command(app, context);
  add_vehicles_command(app, context);
  add_orders_command(app, context);
  add_alarms_command(app, context);
  add_route_command(app, context);

  return run_app(app, context, argc, argv);
}
