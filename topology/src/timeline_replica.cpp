// TimelineSet::replace_timeline: how a routing agent's replica takes in a published timeline.

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

}  // namespace drover::topology
