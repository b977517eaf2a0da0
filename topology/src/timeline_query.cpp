// The free-window query: TimelineSet::append_free_windows (free_windows returns the same),
// with or without a FreeWindowQuery that remembers what each timeline blocks. This file
// holds the rule: the blockers of a step on e are the locks and other agents' reservations
// on e and on the owned members of its conflict set (a step writes on all of them), a held
// (allocated) reservation blocking from `from` on.

#include <algorithm>
#include <cassert>

#include "drover/topology/timeline.hpp"
#include "timeline_impl.hpp"

namespace drover::topology {

namespace {

/// a == b, testing the last character first: the agent ids of a fleet often share a long
/// prefix ("agv-017", "agv-018"), and this runs for every reservation a planner looks at.
bool same_agent(const std::string& a, std::string_view b) {
  return a.size() == b.size() && (b.empty() || a.back() == b.back()) && a == b;
}

void sort_from(std::vector<Interval>& out, std::size_t base) {
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(base), out.end(),
            [](const Interval& a, const Interval& b) { return a.start < b.start; });
}

/// Replaces out[base..] (intervals in any order) by their union: sorted, disjoint.
void merge_from(std::vector<Interval>& out, std::size_t base) {
  sort_from(out, base);
  std::size_t kept = base;
  for (std::size_t i = base; i < out.size(); ++i) {
    if (kept > base && out[i].start <= out[kept - 1].end) {
      out[kept - 1].end = std::max(out[kept - 1].end, out[i].end);
    } else {
      out[kept++] = out[i];
    }
  }
  out.resize(kept);
}

/// Replaces out[base..] (blocked intervals within [from, until), in any order) by the
/// windows between them: sorted, disjoint, maximal. The k-th window is written only after
/// the k-th blocker has been read, so no scratch memory is needed.
void complement_from(std::vector<Interval>& out, std::size_t base, TimeNs from, TimeNs until) {
  sort_from(out, base);
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

void TimelineSet::append_blocked(EntityIndex x, std::string_view agent, TimeNs from,
                                 TimeNs until, bool count_locks,
                                 std::vector<Interval>& out) const {
  const auto block = [&](TimeNs start, TimeNs end) {
    start = std::max(start, from);
    end = std::min(end, until);
    if (start < end) out.push_back(Interval{start, end});
  };
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
}

void TimelineSet::append_free_windows(EntityIndex entity, std::string_view agent, TimeNs from,
                                      TimeNs until, std::vector<Interval>& out,
                                      bool count_locks) const {
  if (!owns(entity) || from >= until) return;
  // The blockers are collected at the end of `out` itself and turned into their complement.
  const std::size_t base = out.size();
  append_blocked(entity, agent, from, until, count_locks, out);
  for (EntityIndex f : conflict_sets_[entity]) {
    if (owns(f)) append_blocked(f, agent, from, until, count_locks, out);
  }
  complement_from(out, base, from, until);
}

void FreeWindowQuery::start(std::string_view agent, TimeNs from, TimeNs until,
                            bool count_locks) {
  agent_.assign(agent);
  from_ = from;
  until_ = until;
  count_locks_ = count_locks;
  if (++generation_ == 0) {  // wrapped: every stamp could look current
    std::fill(stamp_.begin(), stamp_.end(), 0);
    generation_ = 1;
  }
  blocked_.clear();
}

void TimelineSet::append_free_windows(EntityIndex entity, FreeWindowQuery& query,
                                      std::vector<Interval>& out) const {
  assert(query.generation_ != 0 && "FreeWindowQuery::start must come first");
  if (!owns(entity) || query.from_ >= query.until_) return;
  if (query.stamp_.size() != timelines_.size()) {
    query.stamp_.assign(timelines_.size(), 0);
    query.first_.resize(timelines_.size());
    query.count_.resize(timelines_.size());
  }
  const std::size_t base = out.size();
  const auto add_blocked = [&](EntityIndex x) {
    if (query.stamp_[x] != query.generation_) {
      query.stamp_[x] = query.generation_;
      const std::size_t first = query.blocked_.size();
      append_blocked(x, query.agent_, query.from_, query.until_, query.count_locks_,
                     query.blocked_);
      merge_from(query.blocked_, first);
      query.first_[x] = static_cast<std::uint32_t>(first);
      query.count_[x] = static_cast<std::uint32_t>(query.blocked_.size() - first);
    }
    const auto begin = query.blocked_.begin() + query.first_[x];
    out.insert(out.end(), begin, begin + query.count_[x]);
  };
  add_blocked(entity);
  for (EntityIndex f : conflict_sets_[entity]) {
    if (owns(f)) add_blocked(f);
  }
  complement_from(out, base, query.from_, query.until_);
}

}  // namespace drover::topology
