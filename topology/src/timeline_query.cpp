// TimelineSet::append_free_windows: the free-window query of free_windows without a
// returned vector, for planners that ask it for thousands of entities per route.
// It must stay the same function as free_windows (timeline.cpp): the blockers are the
// locks and other agents' reservations on the entity and on the owned members of its
// conflict set, a held (allocated) reservation blocking from `from` on.

#include <algorithm>

#include "drover/topology/timeline.hpp"
#include "timeline_impl.hpp"

namespace drover::topology {

namespace {

/// a == b, testing the last character first: the agent ids of a fleet often share a long
/// prefix ("agv-017", "agv-018"), and this runs for every reservation a planner looks at.
bool same_agent(const std::string& a, std::string_view b) {
  return a.size() == b.size() && (b.empty() || a.back() == b.back()) && a == b;
}

}  // namespace

void TimelineSet::append_free_windows(EntityIndex entity, std::string_view agent, TimeNs from,
                                      TimeNs until, std::vector<Interval>& out,
                                      bool count_locks) const {
  if (!owns(entity) || from >= until) return;
  // The blockers are collected, clipped to [from, until), at the end of `out` itself, sorted
  // there, and turned into their complement in place: the k-th window is written only after
  // the k-th blocker has been read, so no scratch memory is needed.
  const std::size_t base = out.size();
  const auto block = [&](TimeNs start, TimeNs end) {
    start = std::max(start, from);
    end = std::min(end, until);
    if (start < end) out.push_back(Interval{start, end});
  };
  const auto block_timeline = [&](EntityIndex x) {
    const Timeline& t = timelines_[x];
    if (count_locks) {
      for (const Lock& lock : t.locks) block(lock.window.start, lock.window.end);
    }
    for (const Reservation& r : t.reservations) {
      if (same_agent(r.agent, agent)) continue;
      // Nobody may come before a holder: everything up to its end is taken. (Most
      // reservations' origins are not held at all: that is checked first, inline.)
      const bool held = r.window.start > from && r.origin < held_.size() && held_[r.origin] &&
                        Impl::is_held(*this, r);
      block(held ? from : r.window.start, r.window.end);
    }
  };
  block_timeline(entity);
  for (EntityIndex f : conflict_sets_[entity]) {
    if (owns(f)) block_timeline(f);
  }

  const std::size_t blockers = out.size() - base;
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(base), out.end(),
            [](const Interval& a, const Interval& b) { return a.start < b.start; });
  std::size_t windows = 0;
  TimeNs cursor = from;
  for (std::size_t j = 0; j < blockers; ++j) {
    const Interval blocker = out[base + j];
    if (blocker.start > cursor) out[base + windows++] = Interval{cursor, blocker.start};
    cursor = std::max(cursor, blocker.end);
  }
  if (cursor < until) {
    if (windows < blockers) {
      out[base + windows++] = Interval{cursor, until};
    } else {
      out.push_back(Interval{cursor, until});
      ++windows;
    }
  }
  out.resize(base + windows);
}

}  // namespace drover::topology
