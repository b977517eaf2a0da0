// `droverctl agents [--domain N] [--timeout S] [--json]`: lists the live agents of a
// domain from their heartbeats (id, kind, version, what they own). Exit 3 when none
// answers within the timeout.

#include <algorithm>
#include <chrono>
#include <iostream>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "drover/dds/agent_directory.hpp"
#include "drover/dds/participant.hpp"

namespace drover::cli {
namespace {

using namespace std::chrono_literals;

struct AgentsArguments {
  DdsToolOptions dds;
  bool json = false;
};

/// Names of the remote participants present now (discovered, not yet removed or dropped).
class PresentParticipants {
 public:
  void on_event(const dds::ParticipantEvent& event) {
    std::lock_guard lock(mutex_);
    if (event.change == dds::ParticipantChange::discovered) {
      names_.insert(event.name);
    } else {
      names_.erase(event.name);
    }
  }
  std::set<std::string> names() const {
    std::lock_guard lock(mutex_);
    return names_;
  }

 private:
  mutable std::mutex mutex_;
  std::set<std::string> names_;
};

/// Whether every present participant has shown its heartbeat and at least one agent is
/// alive: the listing is then complete (participants without a heartbeat, such as other
/// tools, only make the command wait until its timeout).
bool listing_complete(const std::vector<dds::AgentRecord>& records, const std::set<std::string>& present) {
  const bool any_alive =
      std::any_of(records.begin(), records.end(), [](const dds::AgentRecord& r) { return r.alive; });
  if (!any_alive) return false;
  return std::all_of(present.begin(), present.end(), [&](const std::string& name) {
    return std::any_of(records.begin(), records.end(), [&](const dds::AgentRecord& r) { return r.id == name; });
  });
}

std::set<std::string> agent_ids(const std::vector<dds::AgentRecord>& records) {
  std::set<std::string> ids;
  for (const auto& record : records) ids.insert(record.id);
  return ids;
}

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
  PresentParticipants present;
  const auto token = (*participant)->subscribe_events([&](const dds::ParticipantEvent& e) { present.on_event(e); });
  std::vector<dds::AgentRecord> agents;
  {
    auto directory = dds::AgentDirectory::create(**participant);
    if (!directory) {
      (*participant)->unsubscribe_events(token);
      std::cerr << "error: " << directory.error().message << "\n";
      return kExitFailure;
    }
    // Discovery window: done once every participant present has shown its heartbeat and
    // no new agent appeared for a short while; never later than the timeout. A remote
    // participant is discovered only when it announces itself (every announcement period,
    // 1 s), so the window lasts at least one period and a margin: ending at the first
    // heartbeat would miss agents whose announcement has not arrived yet.
    const auto start = std::chrono::steady_clock::now();
    const auto deadline = start + arguments.dds.timeout();
    const auto listen_at_least_until = start + dds::ParticipantOptions{}.announcement_period + 500ms;
    auto remaining = [&] {
      return std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    };
    auto quiet_period = [&] {
      const auto to_minimum = std::chrono::duration_cast<std::chrono::milliseconds>(
          listen_at_least_until - std::chrono::steady_clock::now());
      return std::min(std::max(300ms, to_minimum), std::max(remaining(), 0ms));
    };
    while (remaining() > 0ms) {
      const bool complete = (*directory)->wait_until(
          [&](const std::vector<dds::AgentRecord>& records) { return listing_complete(records, present.names()); },
          remaining());
      if (!complete) break;
      const auto present_before = present.names();
      const auto ids_before = agent_ids((*directory)->agents());
      (*directory)->wait_until([&](const auto& records) { return agent_ids(records) != ids_before; },
                               quiet_period());
      if (present.names() == present_before && agent_ids((*directory)->agents()) == ids_before) break;
    }
    agents = (*directory)->live_agents();
  }
  (*participant)->unsubscribe_events(token);

  if (agents.empty()) {
    std::cerr << "error: no agent answered on domain " << arguments.dds.domain_id << " within "
              << arguments.dds.timeout_seconds << " s\n";
    return kExitNoAnswer;
  }
  if (arguments.json) {
    print_json(agents);
  } else {
    print_table(agents);
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
