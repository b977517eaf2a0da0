// TimelineSet: who has a reservation where (reserved_entities), kept exact by the two
// places that change a timeline's newcomer windows: revise, and insert's quick path.

#include <algorithm>

#include "drover/topology/timeline.hpp"
#include "timeline_impl.hpp"

namespace drover::topology {

namespace {

/// Inserts `value` into the sorted `values` unless it is there.
template <class T>
void insert_sorted(std::vector<T>& values, T value) {
  const auto at = std::lower_bound(values.begin(), values.end(), value);
  if (at == values.end() || *at != value) values.insert(at, value);
}

/// Removes `value` from the sorted `values`, where it is.
template <class T>
void erase_sorted(std::vector<T>& values, T value) {
  const auto at = std::lower_bound(values.begin(), values.end(), value);
  if (at != values.end() && *at == value) values.erase(at);
}

}  // namespace

std::span<const EntityIndex> TimelineSet::reserved_entities(std::string_view agent) const noexcept {
  const auto found = newcomers_.numbers.find(agent);
  if (found == newcomers_.numbers.end()) return {};
  return newcomers_.entities_of[found->second];
}

std::uint32_t TimelineSet::Impl::agent_number(TimelineSet& set, std::string_view agent) {
  Newcomers& index = set.newcomers_;
  const auto found = index.numbers.find(agent);
  if (found != index.numbers.end()) return found->second;
  const auto number = static_cast<std::uint32_t>(index.entities_of.size());
  index.numbers.emplace(AgentId(agent), number);
  index.entities_of.emplace_back();
  return number;
}

void TimelineSet::Impl::add_reserver(TimelineSet& set, EntityIndex entity, std::uint32_t agent) {
  Newcomers& index = set.newcomers_;
  insert_sorted(index.agents_of[entity], agent);
  insert_sorted(index.entities_of[agent], entity);
}

void TimelineSet::Impl::find_reservers(TimelineSet& set, EntityIndex entity) {
  Newcomers& index = set.newcomers_;
  std::vector<std::uint32_t>& now = index.scratch_agents;
  now.clear();
  const AgentId* last = nullptr;  // a timeline often holds several of one agent's items
  for (const Reservation& r : set.timelines_[entity].reservations) {
    if (last != nullptr && *last == r.agent) continue;
    last = &r.agent;
    now.push_back(agent_number(set, r.agent));
  }
  std::sort(now.begin(), now.end());
  now.erase(std::unique(now.begin(), now.end()), now.end());
  std::vector<std::uint32_t>& before = index.agents_of[entity];
  if (before == now) return;  // the common case: windows moved, the agents did not
  // Both sorted: one pass tells the agents gone from those come.
  auto b = before.begin(), n = now.begin();
  while (b != before.end() || n != now.end()) {
    if (n == now.end() || (b != before.end() && *b < *n)) {
      erase_sorted(index.entities_of[*b++], entity);
    } else if (b == before.end() || *n < *b) {
      insert_sorted(index.entities_of[*n++], entity);
    } else {
      ++b, ++n;
    }
  }
  before = now;
}

bool TimelineSet::Impl::has_reservation(std::span<const EntityIndex> agent_entities,
                                        EntityIndex entity) {
  return std::binary_search(agent_entities.begin(), agent_entities.end(), entity);
}

}  // namespace drover::topology
