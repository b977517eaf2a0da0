// The free-window query: TimelineSet::append_free_windows (free_windows returns the same).
//
// A step on e writes on e and on the owned members f of C(e) (its shadows). prepare refuses
// it where a lock is on one of them, or where another agent's reservation there has an
// origin conflicting with e (I1), and before such a reservation that is held. Every such
// reservation on f has a twin on e itself, with the same agent, step, window and origin o:
// o = e or o in C(e), and the step on o wrote its real reservation on o and a shadow on
// every owned member of C(o), e included (conflict sets are symmetric; a route's items come
// from expand). And every reservation on e has an origin conflicting with e. So e's own
// timeline holds every reservation that blocks e, once; only locks, which write no
// shadows, are read from the members of C(e) (DESIGN's I1: "each entity's own timeline is
// enough"). A held (allocated) reservation blocks from `from` on: nobody comes before it.

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

/// Replaces out[base..] (blocked intervals within [from, until), in any order) by the
/// windows between them: sorted, disjoint, maximal. The k-th window is written only after
/// the k-th blocker has been read, so no scratch memory is needed.
void complement_from(std::vector<Interval>& out, std::size_t base, TimeNs from, TimeNs until) {
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(base), out.end(),
            [](const Interval& a, const Interval& b) { return a.start < b.start; });
  const std::size_t blockers = out.size() - base;
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

}  // namespace

void TimelineSet::append_free_windows(EntityIndex entity, std::string_view agent, TimeNs from,
                                      TimeNs until, std::vector<Interval>& out,
                                      bool count_locks) const {
  if (!owns(entity) || from >= until) return;
  // The blockers are collected at the end of `out` itself and turned into their complement.
  const std::size_t base = out.size();
  const auto block = [&](TimeNs start, TimeNs end) {
    const Interval w{std::max(start, from), std::min(end, until)};
    if (w.valid()) out.push_back(w);
  };
  for (const Reservation& r : timelines_[entity].reservations) {
    if (same_agent(r.agent, agent)) continue;
    // Most reservations' origins are not held at all: that is checked first, inline.
    const bool held = r.window.start > from && r.origin < held_.size() && held_[r.origin] &&
                      Impl::is_held(*this, r);
    block(held ? from : r.window.start, r.window.end);
  }
  if (count_locks) {
    const auto block_locks = [&](EntityIndex x) {
      for (const Lock& lock : timelines_[x].locks) block(lock.window.start, lock.window.end);
    };
    block_locks(entity);
    for (EntityIndex f : conflict_sets_[entity]) {
      if (owns(f)) block_locks(f);
    }
  }
  complement_from(out, base, from, until);
}

}  // namespace drover::topology
