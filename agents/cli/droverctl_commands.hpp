#pragma once
// `droverctl`, the operator tool: every command registers itself on the CLI11 app and
// reports its exit code through CommandContext (0 ok, 1 failure, 2 bad usage or input,
// 3 no agent answered).

#include <CLI/CLI.hpp>

#include "agents/cli/command.hpp"

namespace drover::cli {

/// `droverctl agents`: the live agents, from their heartbeats.
void add_agents_command(CLI::App& app, CommandContext& context);

/// `droverctl route FROM TO`: a test or real route from a routing agent, as JSON.
void add_route_command(CLI::App& app, CommandContext& context);

/// `droverctl order send VEHICLE LOCATION:OPERATION ...`: an order to one logical agent;
/// `droverctl order withdraw VEHICLE ORDER`: withdraws one.
void add_order_command(CLI::App& app, CommandContext& context);
/// `droverctl pause (VEHICLE | --all)`, `droverctl resume (VEHICLE | --all)`: an operator
/// stops a vehicle (or all) at the next vertex and lets it go on; agents/cli/pause_command.cpp.
void add_pause_command(CLI::App& app, CommandContext& context);

/// `droverctl lock ENTITY --from T --until T --reason TEXT`, `droverctl unlock LOCK_ID`,
/// `droverctl timeline ENTITY`: the topology agents' locks and timelines.
void add_lock_command(CLI::App& app, CommandContext& context);
void add_unlock_command(CLI::App& app, CommandContext& context);
void add_timeline_command(CLI::App& app, CommandContext& context);
/// `droverctl release ENTITY --from AGENT`: gives up an allocation a logical agent that is
/// gone left behind.
void add_release_command(CLI::App& app, CommandContext& context);

/// `droverctl orders`: the orders the logical agents know, with their progress;
/// agents/cli/orders_command.cpp.
void add_orders_command(CLI::App& app, CommandContext& context);
/// `droverctl vehicles`: what every vehicle is doing, from its logical agent's state;
/// `droverctl alarms`: shows the alarms the agents keep, then follows them as they are raised.
void add_vehicles_command(CLI::App& app, CommandContext& context);
void add_alarms_command(CLI::App& app, CommandContext& context);

}  // namespace drover::cli
