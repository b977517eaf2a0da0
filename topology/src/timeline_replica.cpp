// TimelineSet::replace_timeline: how a routing agent's replica takes in a published timeline.

#include <map>
#include <tuple>

#include "timeline_impl.hpp"

namespace drover::topology {

Status TimelineSet::replace_timeline(EntityIndex entity, Timeline timeline) {
  if (!owns(entity)) {
    return fail(ErrorCode::not_found,
                "replace_timeline: entity " + std::to_string(entity) + " is not owned by this set");
  }
  held_[entity].reset();
  if (timeline.holder) {
    if (const Reservation* held = Impl::first_committed_real(timeline, *timeline.holder)) {
      held_[entity] = AllocatedStep{held->route, held->step};
    }
  }
  lock_count_ = lock_count_ - timelines_[entity].locks.size() + timeline.locks.size();
  timelines_[entity] = std::move(timeline);
  Impl::revise_around(*this, entity);
  return {};
}

void TimelineSet::widen_to_step_hulls() {
  using StepKey = std::tuple<AgentId, RouteId, std::uint32_t>;
  std::map<StepKey, Interval> hulls;
  for (const Timeline& timeline : timelines_) {
    for (const Reservation& r : timeline.reservations) {
      auto [hull, first] = hulls.try_emplace({r.agent, r.route, r.step}, r.window);
      if (first) continue;
      hull->second.start = std::min(hull->second.start, r.window.start);
      hull->second.end = std::max(hull->second.end, r.window.end);
    }
  }
  for (EntityIndex entity = 0; entity < timelines_.size(); ++entity) {
    Timeline& timeline = timelines_[entity];
    bool widened = false;
    for (Reservation& r : timeline.reservations) {
      const Interval& hull = hulls.at({r.agent, r.route, r.step});
      widened = widened || hull != r.window;
      r.window = hull;
    }
    if (!widened) continue;
    Impl::sort_reservations(timeline);
    Impl::revise(*this, entity, Impl::next_revision());  // other windows, same version
  }
}

}  // namespace drover::topology
