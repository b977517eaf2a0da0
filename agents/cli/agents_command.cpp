// `droverctl agents [--domain N] [--timeout S] [--json]`: lists the live agents of a
// domain from their heartbeats (id, kind, version, what they own). Exit 3 when none
// answers within the timeout.

#include <algorithm>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "agents/cli/agent_discovery.hpp"
#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "drover/dds/agent_directory.hpp"
#include "drover/dds/participant.hpp"

namespace drover::cli {
namespace {

struct AgentsArguments {
  DdsToolOptions dds;
  bool json = false;
};

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : ", ") + item;
  return out.empty() ? "-" : out;
}

void print_table(const std::vector<dds::AgentRecord>& agents) {
  std::size_t id_width = 2;
  std::size_t kind_width = 4;
  std::size_t version_width = 7;
  for (const auto& agent : agents) {
    id_width = std::max(id_width, agent.id.size());
    kind_width = std::max(kind_width, agent.kind.size());
    version_width = std::max(version_width, agent.version.size());
  }
  auto pad = [](const std::string& text, std::size_t width) { return text + std::string(width - text.size() + 2, ' '); };
  std::cout << pad("ID", id_width) << pad("KIND", kind_width) << pad("VERSION", version_width) << "OWNS\n";
  for (const auto& agent : agents) {
    std::cout << pad(agent.id, id_width) << pad(agent.kind, kind_width) << pad(agent.version, version_width)
              << join(agent.owns) << "\n";
  }
}

void print_json(const std::vector<dds::AgentRecord>& agents) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& agent : agents) {
    out.push_back({{"id", agent.id},
                   {"kind", agent.kind},
                   {"version", agent.version},
                   {"owns", agent.owns},
                   {"sim_time_ns", agent.sim_time}});
  }
  std::cout << out.dump() << "\n";
}

int run_agents(const AgentsArguments& arguments) {
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  auto agents = discover_live_agents(**participant, arguments.dds.timeout());
  if (!agents) {
    std::cerr << "error: " << agents.error().message << "\n";
    return kExitFailure;
  }

  if (agents->empty()) {
    std::cerr << "error: no agent answered on domain " << arguments.dds.domain_id << " within "
              << arguments.dds.timeout_seconds << " s\n";
    return kExitNoAnswer;
  }
  if (arguments.json) {
    print_json(*agents);
  } else {
    print_table(*agents);
  }
  return kExitOk;
}

}  // namespace

void add_agents_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<AgentsArguments>();
  auto* command = app.add_subcommand("agents", "List the live agents of a domain from their heartbeats");
  add_dds_tool_options(*command, arguments->dds, 2.0);
  command->add_flag("--json", arguments->json, "Print a JSON array instead of a table");
  command->callback([arguments, &context] { context.exit_code = run_agents(*arguments); });
}

}  // namespace drover::cli
