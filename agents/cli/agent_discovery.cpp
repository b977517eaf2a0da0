#include "agents/cli/agent_discovery.hpp"

#include <algorithm>
#include <mutex>
#include <set>
#include <string>

namespace drover::cli {
namespace {

using namespace std::chrono_literals;

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

}  // namespace

Result<std::vector<dds::AgentRecord>> discover_live_agents(
    dds::Participant& participant, std::chrono::milliseconds timeout,
    const std::function<bool(const std::vector<dds::AgentRecord>&)>& also) {
  PresentParticipants present;
  const auto token = participant.subscribe_events([&](const dds::ParticipantEvent& e) { present.on_event(e); });
  auto directory = dds::AgentDirectory::create(participant);
  if (!directory) {
    participant.unsubscribe_events(token);
    return unexpected(directory.error());
  }
  // Discovery window: done once every participant present has shown its heartbeat and no
  // new agent appeared for a short while; never later than the timeout. A remote
  // participant is discovered only when it announces itself (every announcement period,
  // 1 s), so the window lasts at least one period and a margin: ending at the first
  // heartbeat would miss agents whose announcement has not arrived yet.
  const auto start = std::chrono::steady_clock::now();
  const auto deadline = start + timeout;
  const auto listen_at_least_until = start + dds::ParticipantOptions{}.announcement_period + 500ms;
  auto remaining = [&] {
    return std::max(std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()),
                    0ms);
  };
  auto quiet_period = [&] {
    const auto to_minimum = std::chrono::duration_cast<std::chrono::milliseconds>(
        listen_at_least_until - std::chrono::steady_clock::now());
    return std::min(std::max(300ms, to_minimum), remaining());
  };
  const auto complete = [&](const std::vector<dds::AgentRecord>& records) {
    return listing_complete(records, present.names()) && (!also || also(records));
  };
  while (remaining() > 0ms) {
    // `also` may depend on more than the records: asked again at least every 300 ms.
    if (!(*directory)->wait_until(complete, std::min(remaining(), 300ms))) continue;
    const auto present_before = present.names();
    const auto ids_before = agent_ids((*directory)->agents());
    (*directory)->wait_until([&](const auto& records) { return agent_ids(records) != ids_before; }, quiet_period());
    if (present.names() == present_before && agent_ids((*directory)->agents()) == ids_before) break;
  }
  auto agents = (*directory)->live_agents();
  directory->reset();
  participant.unsubscribe_events(token);
  return agents;
}

std::vector<std::string> live_logical_vehicles(const std::vector<dds::AgentRecord>& agents) {
  std::vector<std::string> vehicles;
  for (const auto& agent : agents) {
    if (agent.kind == "logical" && agent.alive) vehicles.insert(vehicles.end(), agent.owns.begin(), agent.owns.end());
  }
  std::sort(vehicles.begin(), vehicles.end());
  vehicles.erase(std::unique(vehicles.begin(), vehicles.end()), vehicles.end());
  return vehicles;
}

}  // namespace drover::cli
