#include "agents/logical_agent/src/late_grants.hpp"

namespace drover::logical_agent {

void LateGrants::granted(topology::EntityIndex entity, HeldStep step, Clock::time_point now) {
  grants_[entity] = Grant{step, now};
}

std::vector<std::pair<topology::EntityIndex, HeldStep>> LateGrants::to_release(
    const std::function<bool(topology::EntityIndex)>& claimed, std::optional<topology::RouteId> current,
    Clock::time_point now) {
  std::vector<std::pair<topology::EntityIndex, HeldStep>> out;
  for (auto it = grants_.begin(); it != grants_.end();) {
    const auto& [entity, grant] = *it;
    if (claimed(entity)) {
      it = grants_.erase(it);
      continue;
    }
    if (current == grant.step.route && now - grant.at < claim_within_) {
      ++it;
      continue;
    }
    out.emplace_back(entity, grant.step);
    it = grants_.erase(it);
  }
  return out;
}

}  // namespace drover::logical_agent
