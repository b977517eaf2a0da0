// The free-window query: TimelineSet::append_free_windows (free_windows returns the same),
// with or without a FreeWindowQuery that remembers what each timeline blocks. This file
// holds the rule: a step on e writes on e and on the owned members f of C(e); it is blocked
// by the locks there and by other agents' reservations there whose origin conflicts with e
// (I1): every reservation on e, the real ones on f, and shadows on f of e itself or of a
// member of C(e) (a shadow on f of an entity that does not conflict with e stands for a
// reservation e may overlap). A held (allocated) reservation blocks from `from` on.

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

void TimelineSet::Impl::append_blocked(const TimelineSet& set, EntityIndex x,
                                       const BlockRule& rule, std::vector<Interval>& out,
                                       std::vector<ShadowBlock>* shadows) {
  const auto clip = [&](TimeNs start, TimeNs end) {
    return Interval{std::max(start, rule.from), std::min(end, rule.until)};
  };
  const Timeline& t = set.timelines_[x];
  if (rule.count_locks) {
    for (const Lock& lock : t.locks) {
      if (const Interval w = clip(lock.window.start, lock.window.end); w.valid()) out.push_back(w);
    }
  }
  for (const Reservation& r : t.reservations) {
    if (same_agent(r.agent, rule.agent)) continue;
    // A real reservation on x conflicts with every step that writes on x; a shadow only
    // with a step on its origin or on a member of its origin's conflict set (I1).
    const bool real = r.origin == x;
    if (!real && shadows == nullptr && x != rule.entity &&
        !origins_conflict(set, r.origin, rule.entity)) {
      continue;
    }
    // Nobody may come before a holder: everything up to its end is taken. (Most
    // reservations' origins are not held at all: that is checked first, inline.)
    const bool held = r.window.start > rule.from && r.origin < set.held_.size() &&
                      set.held_[r.origin] && is_held(set, r);
    const Interval w = clip(held ? rule.from : r.window.start, r.window.end);
    if (!w.valid()) continue;
    if (real || shadows == nullptr) {
      out.push_back(w);
    } else {
      shadows->push_back(ShadowBlock{w, r.origin});
    }
  }
}

void TimelineSet::append_free_windows(EntityIndex entity, std::string_view agent, TimeNs from,
                                      TimeNs until, std::vector<Interval>& out,
                                      bool count_locks) const {
  if (!owns(entity) || from >= until) return;
  // The blockers are collected at the end of `out` itself and turned into their complement.
  const std::size_t base = out.size();
  const Impl::BlockRule rule{agent, entity, from, until, count_locks};
  Impl::append_blocked(*this, entity, rule, out, nullptr);
  for (EntityIndex f : conflict_sets_[entity]) {
    if (owns(f)) Impl::append_blocked(*this, f, rule, out, nullptr);
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
  shadows_.clear();
}

void TimelineSet::append_free_windows(EntityIndex entity, FreeWindowQuery& query,
                                      std::vector<Interval>& out) const {
  assert(query.generation_ != 0 && "FreeWindowQuery::start must come first");
  if (!owns(entity) || query.from_ >= query.until_) return;
  if (query.stamp_.size() != timelines_.size()) {
    query.stamp_.assign(timelines_.size(), 0);
    query.first_.resize(timelines_.size());
    query.count_.resize(timelines_.size());
    query.shadow_first_.resize(timelines_.size());
    query.shadow_count_.resize(timelines_.size());
  }
  const std::size_t base = out.size();
  // Per timeline, read once per query series: the locks and other agents' real
  // reservations (merged; they block every step writing there) and the other agents'
  // shadows with their origins (which block only steps on entities their origin
  // conflicts with).
  const auto read = [&](EntityIndex x) {
    if (query.stamp_[x] == query.generation_) return;
    query.stamp_[x] = query.generation_;
    const std::size_t first = query.blocked_.size();
    const std::size_t shadow_first = query.shadows_.size();
    const Impl::BlockRule rule{query.agent_, x, query.from_, query.until_, query.count_locks_};
    Impl::append_blocked(*this, x, rule, query.blocked_, &query.shadows_);
    merge_from(query.blocked_, first);
    query.first_[x] = static_cast<std::uint32_t>(first);
    query.count_[x] = static_cast<std::uint32_t>(query.blocked_.size() - first);
    query.shadow_first_[x] = static_cast<std::uint32_t>(shadow_first);
    query.shadow_count_[x] = static_cast<std::uint32_t>(query.shadows_.size() - shadow_first);
  };
  const auto add_blocked = [&](EntityIndex x) {
    read(x);
    const auto begin = query.blocked_.begin() + query.first_[x];
    out.insert(out.end(), begin, begin + query.count_[x]);
    const auto shadow_begin = query.shadows_.begin() + query.shadow_first_[x];
    for (auto s = shadow_begin; s != shadow_begin + query.shadow_count_[x]; ++s) {
      if (x == entity || Impl::origins_conflict(*this, s->origin, entity)) {
        out.push_back(s->window);
      }
    }
  };
  add_blocked(entity);
  for (EntityIndex f : conflict_sets_[entity]) {
    if (owns(f)) add_blocked(f);
  }
  complement_from(out, base, query.from_, query.until_);
}

}  // namespace drover::topology
