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
#include <array>
#include <limits>
#include <span>

#include "drover/topology/timeline.hpp"
#include "timeline_impl.hpp"

namespace drover::topology {

namespace {

/// a == b, testing the last character first: the agent ids of a fleet often share a long
/// prefix ("agv-017", "agv-018"), and this runs for every reservation a planner looks at.
bool same_agent(const std::string& a, std::string_view b) {
  return a.size() == b.size() && (b.empty() || a.back() == b.back()) && a == b;
}

/// What cutting an interval out of sorted, disjoint windows changes: the windows
/// [first, last) overlap it, and what is left of them is pieces[0, count), in order.
struct WindowCut {
  std::size_t first = 0, last = 0;
  std::array<Interval, 2> pieces{};
  std::size_t count = 0;
};

WindowCut plan_cut(std::span<const Interval> windows, Interval cut) {
  const auto first = std::partition_point(windows.begin(), windows.end(),
                                          [&](const Interval& w) { return w.end <= cut.start; });
  const auto last = std::partition_point(first, windows.end(),
                                         [&](const Interval& w) { return w.start < cut.end; });
  WindowCut plan{static_cast<std::size_t>(first - windows.begin()),
                 static_cast<std::size_t>(last - windows.begin())};
  if (first == last) return plan;
  const Interval left{first->start, cut.start};
  const Interval right{cut.end, (last - 1)->end};
  if (left.valid()) plan.pieces[plan.count++] = left;
  if (right.valid()) plan.pieces[plan.count++] = right;
  return plan;
}

}  // namespace

void TimelineSet::Impl::cut_window(std::vector<Interval>& out, std::size_t base, Interval cut) {
  const WindowCut plan = plan_cut(std::span(out).subspan(base), cut);
  if (plan.first == plan.last) return;
  const auto at = out.erase(out.begin() + static_cast<std::ptrdiff_t>(base + plan.first),
                            out.begin() + static_cast<std::ptrdiff_t>(base + plan.last));
  out.insert(at, plan.pieces.begin(), plan.pieces.begin() + static_cast<std::ptrdiff_t>(plan.count));
}

void TimelineSet::Impl::cut_window(NewcomerWindows& windows, Interval cut) {
  const WindowCut plan = plan_cut(windows.windows(), cut);
  if (plan.first == plan.last) return;
  windows.replace(plan.first, plan.last, std::span(plan.pieces).first(plan.count));
}

bool TimelineSet::Impl::clear_for_newcomer(const TimelineSet& set, const Reservation& item,
                                           std::span<const EntityIndex> agent_entities) {
  if (has_reservation(agent_entities, item.entity)) return false;
  const NewcomerWindows& newcomer = set.newcomers_.of[item.entity];
  const std::span<const Interval> windows = newcomer.windows();
  const auto window = std::partition_point(
      windows.begin(), windows.end(), [&](const Interval& w) { return w.end <= item.window.start; });
  return window != windows.end() && window->start <= item.window.start &&
         item.window.end <= window->end;
}

template <class Skip>
void TimelineSet::Impl::sweep(const TimelineSet& set, EntityIndex entity, TimeNs from,
                              TimeNs until, std::vector<Interval>& out, bool count_locks,
                              Skip skip) {
  if (!set.owns(entity) || from >= until) return;
  // One sweep over the reservations, which are sorted by start: a window ends where the
  // next blocker starts. Then the locks, rare, are cut out.
  const std::size_t base = out.size();
  TimeNs cursor = from;  // the end of everything blocked so far
  for (const Reservation& r : set.timelines_[entity].reservations) {
    if (skip(r)) continue;
    // Most reservations' origins are not held at all: that is checked first, inline.
    if (r.window.start > from && r.origin < set.held_.size() && set.held_[r.origin] &&
        is_held(set, r)) {
      out.resize(base);  // nobody may come before a holder
    } else if (r.window.start > cursor && cursor < until) {
      out.push_back(Interval{cursor, std::min(r.window.start, until)});
    }
    cursor = std::max(cursor, r.window.end);
  }
  if (cursor < until) out.push_back(Interval{cursor, until});
  if (count_locks && set.lock_count_ > 0) {
    const auto cut_locks = [&](EntityIndex x) {
      for (const Lock& lock : set.timelines_[x].locks) cut_window(out, base, lock.window);
    };
    cut_locks(entity);
    for (EntityIndex f : set.conflict_sets_[entity]) {
      if (!set.timelines_[f].locks.empty() && set.owns(f)) cut_locks(f);
    }
  }
}

void TimelineSet::append_free_windows(EntityIndex entity, std::string_view agent, TimeNs from,
                                      TimeNs until, std::vector<Interval>& out,
                                      bool count_locks) const {
  // An agent with no reservation on the entity sees the newcomer's windows (kept up to date,
  // locks counted), clipped to [from, until): the same answer as a sweep started at `from`
  // (a holder starting by then only drops windows that end before it), without reading
  // the reservations. A planner asks this for every start and goal it checks.
  if (count_locks && owns(entity) && from < until) {
    if (!Impl::has_reservation(reserved_entities(agent), entity)) {
      for (const Interval& w : newcomers_.of[entity].windows()) {
        if (w.end <= from) continue;
        if (w.start >= until) break;
        out.push_back(Interval{std::max(w.start, from), std::min(w.end, until)});
      }
      return;
    }
  }
  Impl::sweep(*this, entity, from, until, out, count_locks,
              [agent](const Reservation& r) { return same_agent(r.agent, agent); });
}

void TimelineSet::Impl::revise(TimelineSet& set, EntityIndex entity, std::uint64_t revision) {
  set.revisions_.of[entity] = revision;
  NewcomerWindows& newcomer = set.newcomers_.of[entity];
  std::vector<Interval>& windows = set.newcomers_.scratch;
  windows.clear();
  newcomer.clear();
  std::vector<std::uint32_t>& agents = set.newcomers_.scratch_agents;
  agents.clear();
  const AgentId* last = nullptr;  // a timeline often holds several of one agent's items
  sweep(set, entity, std::numeric_limits<TimeNs>::min(), kForever, windows, true,
        [&](const Reservation& r) {
          if (last == nullptr || *last != r.agent) agents.push_back(agent_number(set, r.agent));
          last = &r.agent;
          return false;
        });
  newcomer.assign(windows);
  set_reservers(set, entity, agents);
}

std::uint64_t TimelineSet::windows_revision(EntityIndex entity) const noexcept {
  return entity < revisions_.of.size() ? revisions_.of[entity] : 0;
}

}  // namespace drover::topology
