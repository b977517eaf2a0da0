// `droverctl release ENTITY --from AGENT`: an operator gives up an allocation that a logical
// agent which is gone left behind (its vehicle towed off the floor, say): on the topology
// agent owning the entity, and the allocated step's shadows on the others. Refused while
// AGENT is alive: a running logical agent releases what it holds itself, once its vehicle
// has left it, and only it knows where the vehicle is.

#include <algorithm>
#include <iostream>
#include <memory>
#include <string>

#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "agents/cli/topology_tool.hpp"
#include "agents/topology_agent/topology_agent.hpp"
#include "drover/dds/agent_directory.hpp"
#include "drover/dds/service_client.hpp"

namespace drover::cli {
namespace {

struct ReleaseArguments {
  DdsToolOptions dds;
  std::string entity;
  std::string agent;
};

using ReleaseClient = dds::ServiceClient<msg::ReleaseRequest, msg::StatusReply>;

/// The route step `agent` holds `entity` under, as its owner says. \return it, or an
/// error to print with its exit code.
Result<msg::HeldAllocation> held_step(dds::Participant& participant, const ReleaseArguments& arguments,
                                      const std::string& owner) {
  auto client = dds::ServiceClient<msg::HoldingsRequest, msg::HoldingsReply>::create(participant, "topology",
                                                                                     "holdings");
  if (!client) return unexpected(client.error());
  msg::HoldingsRequest request;
  request.agent(arguments.agent);
  auto reply = (*client)->call(request, arguments.dds.timeout(), owner);
  if (!reply) {
    return fail(ErrorCode::unavailable, "topology agent '" + owner + "' did not answer: " + reply.error().message);
  }
  if (reply->error().code() != msg::ERROR_NONE) {
    return fail(ErrorCode::internal, "topology agent '" + owner + "' refused: " + reply->error().message());
  }
  for (const auto& held : reply->held()) {
    if (held.entity() == arguments.entity) return held;
  }
  return fail(ErrorCode::not_found,
              "'" + arguments.agent + "' does not hold '" + arguments.entity + "' (topology agent '" + owner + "')");
}

int run_release(const ReleaseArguments& arguments) {
  if (arguments.agent.empty()) {
    std::cerr << "error: --from must name the agent that holds the entity\n";
    return kExitBadInput;
  }
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  auto directory = dds::AgentDirectory::create(**participant);
  if (!directory) {
    std::cerr << "error: " << directory.error().message << "\n";
    return kExitFailure;
  }
  auto owner = find_owner(**participant, arguments.entity, arguments.dds.timeout());
  if (!owner) {
    std::cerr << "error: " << owner.error().message << " on domain " << arguments.dds.domain_id << " within "
              << arguments.dds.timeout_seconds << " s\n";
    return exit_code_of(owner.error());
  }
  // The domain's heartbeats reach us (the owner's did): a live agent's come within two
  // deadlines.
  if ((*directory)->wait_for_agent(arguments.agent, true, 2 * dds::kHeartbeatDeadline)) {
    std::cerr << "error: '" << arguments.agent
              << "' is alive: it releases what it holds itself once its vehicle has left (stop its logical agent "
                 "first if the vehicle is gone)\n";
    return kExitFailure;
  }
  auto held = held_step(**participant, arguments, owner->id);
  if (!held) {
    std::cerr << "error: " << held.error().message << "\n";
    return held.error().code == ErrorCode::unavailable ? kExitNoAnswer : kExitFailure;
  }
  auto client = ReleaseClient::create(**participant, "topology", "release");
  if (!client) {
    std::cerr << "error: " << client.error().message << "\n";
    return kExitFailure;
  }
  msg::ReleaseRequest request;
  request.agent(arguments.agent);
  request.entity(arguments.entity);
  request.route(held->route());
  request.step(held->step());
  int exit_code = kExitOk;
  if (!call_topology_agent(**client, request, arguments.dds.timeout(), owner->id, exit_code)) return exit_code;
  // The step's shadows on entities other partitions own go there (each agent drops those it
  // has; an agent without any answers as much).
  request.shadows_only(true);
  for (const auto& agent : (*directory)->live_agents()) {
    // Another agent serving the owner's partitions (a standby) has no shadows of its own to drop.
    const bool shares_partition = std::any_of(agent.owns.begin(), agent.owns.end(), [&](const std::string& p) {
      return std::find(owner->owns.begin(), owner->owns.end(), p) != owner->owns.end();
    });
    if (agent.kind != "topology" || agent.id == owner->id || shares_partition) continue;
    auto shadows = (*client)->call(request, arguments.dds.timeout(), agent.id);
    const std::string problem = !shadows ? shadows.error().message
                                : shadows->error().code() != msg::ERROR_NONE ? shadows->error().message()
                                                                              : "";
    if (!problem.empty()) {
      std::cerr << "warning: the shadows of '" << arguments.entity << "' on topology agent '" << agent.id
                << "' stay (they go with route " << held->route() << "): " << problem << "\n";
      exit_code = kExitFailure;
    }
  }
  std::cout << "released " << arguments.entity << " from " << arguments.agent << " (route " << held->route()
            << " step " << held->step() << ")\n";
  return exit_code;
}

}  // namespace

void add_release_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<ReleaseArguments>();
  auto* command = app.add_subcommand(
      "release", "Give up an allocation that a logical agent which is gone left (refused while it is alive)");
  command->add_option("ENTITY", arguments->entity, "Entity id (vertex or edge)")->required()->check(cli::identifier());
  command->add_option("--from", arguments->agent, "The agent holding it (as the operator alarm names it)")
      ->required();
  add_dds_tool_options(*command, arguments->dds, 5.0);
  command->callback([arguments, &context] { context.exit_code = run_release(*arguments); });
}

}  // namespace drover::cli
