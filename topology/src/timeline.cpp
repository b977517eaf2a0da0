// TimelineSet: construction, queries (expand, free windows), locks and the helpers shared
// by the other timeline sources. Prepare/commit live in timeline_prepare.cpp, allocation in
// timeline_allocation.cpp, delay propagation in timeline_delay.cpp, the free-window sweep
// in timeline_query.cpp.

#include <algorithm>
#include <atomic>
#include <cassert>
#include <functional>
#include <string>
#include <tuple>
#include <utility>

#include "drover/topology/timeline.hpp"
#include "timeline_impl.hpp"

namespace drover::topology {
namespace {

/// Drops out-of-range indices and self references; sorts and deduplicates each set.
std::vector<std::vector<EntityIndex>> clean_conflict_sets(
    std::vector<std::vector<EntityIndex>> sets) {
  const std::size_t count = sets.size();
  for (std::size_t e = 0; e < count; ++e) {
    auto& set = sets[e];
    std::erase_if(set, [&](EntityIndex f) { return f >= count || f == e; });
    std::sort(set.begin(), set.end());
    set.erase(std::unique(set.begin(), set.end()), set.end());
  }
  return sets;
}

std::vector<bool> owned_flags(std::vector<bool> owned, std::size_t count) {
  if (owned.empty()) return std::vector<bool>(count, true);
  owned.resize(count, false);
  return owned;
}

}  // namespace

// ---- shared helpers -------------------------------------------------------------------

bool TimelineSet::Impl::timeline_order(const Reservation& a, const Reservation& b) {
  return std::tie(a.window.start, a.window.end, a.agent, a.route, a.step, a.origin) <
         std::tie(b.window.start, b.window.end, b.agent, b.route, b.step, b.origin);
}

void TimelineSet::Impl::sort_reservations(Timeline& timeline) {
  std::sort(timeline.reservations.begin(), timeline.reservations.end(), timeline_order);
}

void TimelineSet::Impl::bump_versions(TimelineSet& set, const TouchedSet& touched,
                                      Windows windows) {
  const std::uint64_t revision = next_revision();
  for (EntityIndex entity : touched) {
    ++set.timelines_[entity].version;
    if (windows == Windows::changed) {
      revise(set, entity, revision);
    } else if (windows == Windows::updated) {
      set.revisions_.of[entity] = revision;
    }
  }
}

std::uint64_t TimelineSet::Impl::next_revision() {
  static std::atomic<std::uint64_t> last{0};
  return last.fetch_add(1, std::memory_order_relaxed) + 1;
}

void TimelineSet::Impl::revise_all(TimelineSet& set) {
  const std::uint64_t revision = next_revision();
  for (EntityIndex e = 0; e < set.revisions_.of.size(); ++e) revise(set, e, revision);
}

void TimelineSet::Impl::revise_around(TimelineSet& set, EntityIndex entity) {
  const std::uint64_t revision = next_revision();
  revise(set, entity, revision);
  for (EntityIndex f : set.conflict_sets_[entity]) revise(set, f, revision);
}

bool TimelineSet::Impl::in_conflict_set(const TimelineSet& set, EntityIndex origin,
                                        EntityIndex entity) {
  const auto& conflicts = set.conflict_sets_[origin];
  return std::binary_search(conflicts.begin(), conflicts.end(), entity);
}

bool TimelineSet::Impl::origins_conflict(const TimelineSet& set, EntityIndex a,
                                         EntityIndex b) {
  return a == b || in_conflict_set(set, a, b);
}

bool TimelineSet::Impl::is_held(const TimelineSet& set, const Reservation& r) {
  if (!set.owns(r.origin)) return false;
  const auto& held = set.held_[r.origin];
  return held && set.timelines_[r.origin].holder == r.agent && held->route == r.route &&
         held->step == r.step;
}

void TimelineSet::Impl::remove_reservations(
    TimelineSet& set, const std::function<bool(const Reservation&)>& doomed,
    TouchedSet& touched) {
  for (EntityIndex entity = 0; entity < set.timelines_.size(); ++entity) {
    if (std::erase_if(set.timelines_[entity].reservations, doomed) > 0) touched.insert(entity);
  }
}

// ---- construction and queries ----------------------------------------------------------

TimelineSet::TimelineSet(std::vector<std::vector<EntityIndex>> conflict_sets,
                         std::vector<bool> owned)
    : conflict_sets_(clean_conflict_sets(std::move(conflict_sets))),
      owned_(owned_flags(std::move(owned), conflict_sets_.size())),
      owns_all_(std::find(owned_.begin(), owned_.end(), false) == owned_.end()),
      timelines_(conflict_sets_.size()),
      held_(conflict_sets_.size()),
      revisions_{std::vector<std::uint64_t>(conflict_sets_.size())},
      newcomers_{std::vector<NewcomerWindows>(conflict_sets_.size()), {}, {},
                 std::vector<std::vector<std::uint32_t>>(conflict_sets_.size()), {}, {}} {
  Impl::revise_all(*this);
}

std::size_t TimelineSet::entity_count() const noexcept { return timelines_.size(); }

std::size_t TimelineSet::lock_count() const noexcept { return lock_count_; }

bool TimelineSet::owns(EntityIndex entity) const noexcept {
  return entity < owned_.size() && owned_[entity];
}

const Timeline& TimelineSet::timeline(EntityIndex entity) const {
  assert(entity < timelines_.size());
  return timelines_[entity];
}

std::uint64_t TimelineSet::version(EntityIndex entity) const {
  return entity < timelines_.size() ? timelines_[entity].version : 0;
}

std::vector<Reservation> TimelineSet::expand(const AgentId& agent, RouteId route,
                                             const std::vector<RouteStep>& steps) const {
  std::vector<Reservation> items;
  // Sized once: grown by doubling, the items (72 bytes each, hundreds per route) were
  // copied about once more each, into memory fresh to the caches.
  std::size_t count = steps.size();
  for (const RouteStep& s : steps) {
    if (s.entity < conflict_sets_.size()) count += conflict_sets_[s.entity].size();
  }
  items.reserve(count);
  for (std::uint32_t step = 0; step < steps.size(); ++step) {
    const RouteStep& s = steps[step];
    items.push_back(Reservation{agent, route, step, s.entity, s.entity, s.window, false});
    if (s.entity >= conflict_sets_.size()) continue;  // prepare reports it
    for (EntityIndex f : conflict_sets_[s.entity]) {
      items.push_back(Reservation{agent, route, step, f, s.entity, s.window, false});
    }
  }
  return items;
}

std::vector<Interval> TimelineSet::free_windows(EntityIndex entity, const AgentId& agent,
                                                TimeNs from, TimeNs until) const {
  // One implementation of the query: the planner's allocation-free sweep. (A Boost.ICL
  // interval_set was used here first; it measured ten times slower on a busy timeline,
  // and the planner asks this for thousands of entities per route.)
  std::vector<Interval> windows;
  append_free_windows(entity, agent, from, until, windows);
  return windows;
}

// ---- locks --------------------------------------------------------------------------------

Result<LockReport> TimelineSet::lock(EntityIndex entity, Interval window,
                                     std::string operator_id, std::string reason) {
  if (!window.valid()) {
    return fail(ErrorCode::invalid_argument,
                "lock: window [" + std::to_string(window.start) + ", " +
                    std::to_string(window.end) + ") of entity " + std::to_string(entity) +
                    " is empty or reversed");
  }
  // Planning adds to the ends of what blocks an entity: they stay where that cannot overflow.
  if (window.start < 0 || (window.end > kLatestTime && window.end != kForever)) {
    return fail(ErrorCode::invalid_argument,
                "lock: window [" + std::to_string(window.start) + ", " + std::to_string(window.end) + ") of entity " +
                    std::to_string(entity) + " is outside the shared clock's range [0, " +
                    std::to_string(kLatestTime) + "] (its end may also be forever)");
  }
  if (operator_id.empty()) {
    return fail(ErrorCode::invalid_argument,
                "lock: entity " + std::to_string(entity) + ": empty operator id");
  }
  if (!owns(entity)) {
    return fail(ErrorCode::not_found,
                "lock: entity " + std::to_string(entity) + " is not owned by this set");
  }
  Timeline& t = timelines_[entity];
  LockReport report;
  report.id = next_lock_id_++;
  for (const Reservation& r : t.reservations) {
    if (r.window.overlaps(window)) report.hit.push_back(r);
  }
  t.locks.push_back(Lock{report.id, entity, window, std::move(operator_id), std::move(reason)});
  ++lock_count_;
  std::sort(t.locks.begin(), t.locks.end(), [](const Lock& a, const Lock& b) {
    return std::tie(a.window.start, a.id) < std::tie(b.window.start, b.id);
  });
  lock_entities_.emplace(report.id, entity);
  ++t.version;
  Impl::revise_around(*this, entity);
  return report;
}

Status TimelineSet::unlock(LockId id) {
  const auto found = lock_entities_.find(id);
  if (found == lock_entities_.end()) {
    return fail(ErrorCode::not_found, "unlock: no lock with id " + std::to_string(id));
  }
  Timeline& t = timelines_[found->second];
  lock_count_ -= std::erase_if(t.locks, [&](const Lock& lock) { return lock.id == id; });
  ++t.version;
  Impl::revise_around(*this, found->second);
  lock_entities_.erase(found);
  return {};
}

}  // namespace drover::topology
