// `droverctl unlock LOCK_ID`: removes a lock. Lock ids are "<topology agent id>/<number>",
// so the id names the agent to ask.

#include <iostream>
#include <memory>
#include <string>

#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "agents/topology_agent/topology_agent.hpp"
#include "drover/dds/service_client.hpp"

namespace drover::cli {
namespace {

struct UnlockArguments {
  DdsToolOptions dds;
  std::string lock_id;
};

int run_unlock(const UnlockArguments& arguments) {
  const auto slash = arguments.lock_id.rfind('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == arguments.lock_id.size()) {
    std::cerr << "error: '" << arguments.lock_id
              << "' is not a lock id (lock ids are <topology agent id>/<number>, as droverctl lock printed)\n";
    return kExitBadInput;
  }
  const std::string agent = arguments.lock_id.substr(0, slash);
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  auto client = dds::ServiceClient<msg::UnlockRequest, msg::StatusReply>::create(**participant, "topology", "unlock");
  if (!client) {
    std::cerr << "error: " << client.error().message << "\n";
    return kExitFailure;
  }
  msg::UnlockRequest request;
  request.lock_id(arguments.lock_id);
  auto reply = (*client)->call(request, arguments.dds.timeout(), agent);
  if (!reply) {
    std::cerr << "error: topology agent '" << agent << "' did not answer on domain " << arguments.dds.domain_id
              << ": " << reply.error().message << "\n";
    return kExitNoAnswer;
  }
  if (reply->error().code() != msg::ERROR_NONE) {
    std::cerr << "error: topology agent '" << agent << "' refused: " << reply->error().message() << "\n";
    return kExitFailure;
  }
  std::cout << "unlocked " << arguments.lock_id << "\n";
  return kExitOk;
}

}  // namespace

void add_unlock_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<UnlockArguments>();
  auto* command = app.add_subcommand("unlock", "Remove a lock");
  command->add_option("LOCK_ID", arguments->lock_id, "Lock id, as droverctl lock printed (<agent>/<n>)")->required();
  add_dds_tool_options(*command, arguments->dds, 5.0);
  command->callback([arguments, &context] { context.exit_code = run_unlock(*arguments); });
}

}  // namespace drover::cli
