// TimelineSet: who has a reservation where (reserved_entities), kept exact by the two
// places that change a timeline's newcomer windows: revise, and insert's quick path.

#include <algorithm>
#include <iterator>

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

template <class T>
void sort_unique(std::vector<T>& values) {
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
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

void TimelineSet::Impl::add_reservers(TimelineSet& set, std::uint32_t agent,
                                      std::vector<EntityIndex>& entities) {
  Newcomers& index = set.newcomers_;
  sort_unique(entities);
  for (const EntityIndex entity : entities) insert_sorted(index.agents_of[entity], agent);
  // One merge for the agent's list: inserting a route's hundreds of entities one by one
  // cost reserve 6 % more instructions (bench plan, warehouse N = 400).
  std::vector<EntityIndex>& mine = index.entities_of[agent];
  std::vector<EntityIndex> merged;
  merged.reserve(mine.size() + entities.size());
  std::set_union(mine.begin(), mine.end(), entities.begin(), entities.end(),
                 std::back_inserter(merged));
  mine.swap(merged);
}

void TimelineSet::Impl::set_reservers(TimelineSet& set, EntityIndex entity,
                                      std::vector<std::uint32_t>& agents) {
  Newcomers& index = set.newcomers_;
  sort_unique(agents);
  std::vector<std::uint32_t>& before = index.agents_of[entity];
  if (before == agents) return;  // the common case: windows moved, the agents did not
  // Both sorted: one pass tells the agents gone from those come.
  auto b = before.begin(), n = agents.begin();
  while (b != before.end() || n != agents.end()) {
    if (n == agents.end() || (b != before.end() && *b < *n)) {
      erase_sorted(index.entities_of[*b++], entity);
    } else if (b == before.end() || *n < *b) {
      insert_sorted(index.entities_of[*n++], entity);
    } else {
      ++b, ++n;
    }
  }
  before = agents;
}

bool TimelineSet::Impl::has_reservation(std::span<const EntityIndex> agent_entities,
                                        EntityIndex entity) {
  return std::binary_search(agent_entities.begin(), agent_entities.end(), entity);
}

}  // namespace drover::topology
