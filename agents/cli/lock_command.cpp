// `droverctl lock ENTITY --from T --until T --reason TEXT [--operator ID]`: locks an entity
// on the topology agent that owns it; prints the lock id, then one line per reservation the
// lock hit (their owners are notified by the agent).

#include <iostream>
#include <memory>
#include <string>

#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "agents/cli/topology_tool.hpp"
#include "agents/topology_agent/topology_agent.hpp"
#include "drover/dds/service_client.hpp"

namespace drover::cli {
namespace {

struct LockArguments {
  DdsToolOptions dds;
  std::string entity;
  std::string from;
  std::string until;
  std::string reason;
  std::string operator_id;
};

std::string end_text(TimeNs end) { return end == kForever ? std::string("forever") : std::to_string(end); }

int run_lock(const LockArguments& arguments) {
  if (arguments.reason.empty()) {
    std::cerr << "error: --reason must not be empty\n";
    return kExitBadInput;
  }
  // The times' forms are checked before anything goes on the network, and so is their
  // order where it does not depend on the owner's clock (both absolute, or both relative).
  const auto from_form = parse_time(arguments.from, 0, false);
  const auto until_form = parse_time(arguments.until, 0, true);
  if (!from_form || !until_form) {
    std::cerr << "error: " << (from_form ? "--until: " + until_form.error().message : "--from: " + from_form.error().message)
              << "\n";
    return kExitBadInput;
  }
  if (*until_form != kForever && relative_time(arguments.from) == relative_time(arguments.until) &&
      *from_form >= *until_form) {
    std::cerr << "error: --from " << arguments.from << " is not before --until " << arguments.until << "\n";
    return kExitBadInput;
  }
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  auto owner = find_owner(**participant, arguments.entity, arguments.dds.timeout());
  if (!owner) {
    std::cerr << "error: " << owner.error().message << " on domain " << arguments.dds.domain_id << " within "
              << arguments.dds.timeout_seconds << " s\n";
    return exit_code_of(owner.error());
  }
  // Relative times count from the owner's clock as of its last heartbeat.
  auto from = parse_time(arguments.from, owner->sim_time, false);
  auto until = parse_time(arguments.until, owner->sim_time, true);
  if (!from || !until) {
    std::cerr << "error: " << (from ? "--until: " + until.error().message : "--from: " + from.error().message) << "\n";
    return kExitBadInput;
  }
  if (*from >= *until) {
    std::cerr << "error: --from " << *from << " is not before --until " << end_text(*until) << "\n";
    return kExitBadInput;
  }
  auto client = dds::ServiceClient<msg::LockRequest, msg::LockReply>::create(**participant, "topology", "lock");
  if (!client) {
    std::cerr << "error: " << client.error().message << "\n";
    return kExitFailure;
  }
  msg::LockRequest request;
  request.entity(arguments.entity);
  request.window().start(*from);
  request.window().end(*until);
  request.operator_id(arguments.operator_id.empty() ? (*participant)->agent_id() : arguments.operator_id);
  request.reason(arguments.reason);
  int exit_code = kExitOk;
  const auto reply = call_topology_agent(**client, request, arguments.dds.timeout(), owner->id, exit_code);
  if (!reply) return exit_code;
  std::cout << reply->lock_id() << "\n";
  for (const auto& hit : reply->hit()) {
    std::cout << "hit: " << hit.agent() << " route " << hit.route() << " step " << hit.step() << " on "
              << hit.entity() << (hit.origin() != hit.entity() ? " (shadow of " + hit.origin() + ")" : "") << " ["
              << hit.window().start() << ", " << end_text(hit.window().end()) << ")\n";
  }
  return kExitOk;
}

}  // namespace

void add_lock_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<LockArguments>();
  auto* command = app.add_subcommand("lock", "Lock an entity for an interval (no new reservations on it then)");
  command->add_option("ENTITY", arguments->entity, "Entity id (vertex or edge)")->required()->check(cli::identifier());
  command->add_option("--from", arguments->from, "Start: shared-clock ns, 'now' or '+30s' (units ns us ms s m h)")
      ->required();
  command->add_option("--until", arguments->until, "End (exclusive): as --from, or 'forever'")->required();
  command->add_option("--reason", arguments->reason, "Why (shown to operators and in the timeline)")->required();
  command->add_option("--operator", arguments->operator_id, "Operator id (default: droverctl-<pid>)")
      ->check(cli::identifier());
  add_dds_tool_options(*command, arguments->dds, 5.0);
  command->callback([arguments, &context] { context.exit_code = run_lock(*arguments); });
}

}  // namespace drover::cli
