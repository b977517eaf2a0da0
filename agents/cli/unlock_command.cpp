// `droverctl unlock LOCK_ID`: removes a lock. Lock ids are "<topology agent id>/<number>",
// so the id names the agent to ask.

#include <algorithm>
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
  // <agent id>/<number>, the number as the topology agent wrote it (no sign, no leading
  // zero): "t/01" naming lock 1 would remove a lock that nobody named.
  const auto slash = arguments.lock_id.rfind('/');
  const std::string agent = slash == std::string::npos ? std::string() : arguments.lock_id.substr(0, slash);
  const std::string number = slash == std::string::npos ? std::string() : arguments.lock_id.substr(slash + 1);
  const bool digits_only = !number.empty() && std::all_of(number.begin(), number.end(), [](char c) {
    return c >= '0' && c <= '9';
  });
  if (!dds::validate_agent_id(agent) || !digits_only || (number.size() > 1 && number.front() == '0')) {
    std::cerr << "error: '" << arguments.lock_id
              << "' is not a lock id (lock ids are <topology agent id>/<number>, as droverctl lock printed)\n";
    return kExitBadInput;
  }
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
