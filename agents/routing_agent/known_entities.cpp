#include "agents/routing_agent/known_entities.hpp"

#include <algorithm>
#include <deque>
#include <set>

namespace drover::routing_agent {

bool KnownEntities::add(const msg::EntityDescription& description) {
  auto [it, inserted] = entities_.try_emplace(description.id(), description);
  if (!inserted) {
    if (it->second == description) return false;
    it->second = description;
  }
  ++generation_;
  return true;
}

const msg::EntityDescription* KnownEntities::find(const std::string& id) const {
  auto it = entities_.find(id);
  return it == entities_.end() ? nullptr : &it->second;
}

std::optional<MissingEntity> KnownEntities::first_missing(const std::string& start,
                                                          const std::vector<std::string>& stops) {
  if (!find(start)) return MissingEntity{start, {}};
  for (const auto& stop : stops) {
    if (!find(stop)) return MissingEntity{stop, {}};
  }
  if (complete_generation_ == generation_ &&
      std::find(complete_starts_.begin(), complete_starts_.end(), start) != complete_starts_.end()) {
    return std::nullopt;
  }

  // Breadth-first over the drivable component; `traversed` holds every entity queued. An
  // entity first met as a conflict member is only checked, and still traversed when it is
  // reached by driving later (its own conflicts must then be complete too).
  std::set<std::string> traversed{start};
  std::deque<const msg::EntityDescription*> queue{find(start)};
  auto need = [&](const std::string& id, const std::string& by,
                  bool traverse) -> std::optional<MissingEntity> {
    const auto* description = find(id);
    if (description == nullptr) return MissingEntity{id, by};
    if (traverse && traversed.insert(id).second) queue.push_back(description);
    return std::nullopt;
  };
  while (!queue.empty()) {
    const msg::EntityDescription& entity = *queue.front();
    queue.pop_front();
    if (entity.kind() == msg::ENTITY_VERTEX) {
      for (const auto& edge : entity.out_edges()) {
        if (auto missing = need(edge, entity.id(), true)) return missing;
      }
    } else {
      for (const auto* end : {&entity.from(), &entity.to()}) {
        if (auto missing = need(*end, entity.id(), true)) return missing;
      }
    }
    for (const auto& other : entity.conflicts()) {
      if (auto missing = need(other, entity.id(), false)) return missing;
      const auto* conflicting = find(other);
      if (conflicting->kind() != msg::ENTITY_EDGE) continue;
      for (const auto* end : {&conflicting->from(), &conflicting->to()}) {
        if (!find(*end)) return MissingEntity{*end, other};
      }
    }
  }
  if (complete_generation_ != generation_) {
    complete_starts_.clear();
    complete_generation_ = generation_;
  }
  complete_starts_.push_back(start);
  return std::nullopt;
}

}  // namespace drover::routing_agent
