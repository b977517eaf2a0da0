// TimelineSet::delay: delay propagation that keeps the order on every timeline (I3).
//
// A route's movement is a non-decreasing step function over its step indices: level(k) is
// how much later step k starts, and step k ends level(k + 1) later (it waits that much
// longer before moving on). The delayed route starts with level(d + 1) = by. Whenever a
// reservation Y of one agent starts before a reservation X of another agent that came
// before it on the same timeline ends, Y's route gets level(step of Y) >= X's new end -
// Y's start: it waits at its previous step until X is gone. Only X and Y whose origins
// conflict constrain each other (I1): shadows of two non-conflicting entities may overlap
// and keep no order. Levels only rise, each to the least value that satisfies its
// constraint, so the result is the least fixpoint
// (independent of the order of work). It exists and stays <= by everywhere, as shifting
// every route by `by` satisfies every constraint, so the iteration ends.
// Everything is computed first and applied only when no time would overflow: atomic.

#include <algorithm>
#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include "drover/topology/timeline.hpp"
#include "timeline_impl.hpp"

namespace drover::topology {
namespace {

using RouteKey = std::pair<AgentId, RouteId>;

RouteKey key_of(const Reservation& r) { return {r.agent, r.route}; }

/// The levels of one route: level(k) = value of the last entry at or before k (0 if none).
/// Entries rise strictly with the step, so lookups are a single map search.
class RouteLevels {
 public:
  DurationNs at(std::uint64_t step) const {
    auto after = entries_.upper_bound(step);
    return after == entries_.begin() ? 0 : std::prev(after)->second;
  }
  /// Makes level(k) >= level for every k >= from. \return true if anything rose.
  bool raise(std::uint64_t from, DurationNs level) {
    if (at(from) >= level) return false;
    entries_[from] = level;
    for (auto it = entries_.upper_bound(from); it != entries_.end() && it->second <= level;) {
      it = entries_.erase(it);
    }
    return true;
  }
  /// The first step whose window moves: the step before the first raised one ends later.
  std::uint32_t first_moved_step() const {
    const std::uint64_t first = entries_.begin()->first;
    return static_cast<std::uint32_t>(first == 0 ? 0 : first - 1);
  }
  DurationNs largest() const { return entries_.empty() ? 0 : entries_.rbegin()->second; }

 private:
  std::map<std::uint64_t, DurationNs> entries_;
};

/// `time` + `shift`, or kForever where that would pass the end of the TimeNs range.
TimeNs shifted(TimeNs time, DurationNs shift) {
  TimeNs sum = 0;
  return __builtin_add_overflow(time, shift, &sum) ? kForever : sum;
}

/// The new window of `r` under its route's levels; nullopt when a time would reach
/// kForever (or overflow).
std::optional<Interval> moved_window(const Reservation& r, const RouteLevels& levels) {
  Interval w = r.window;
  if (__builtin_add_overflow(w.start, levels.at(r.step), &w.start) || w.start == kForever) {
    return std::nullopt;
  }
  if (w.end != kForever &&
      (__builtin_add_overflow(w.end, levels.at(std::uint64_t{r.step} + 1), &w.end) ||
       w.end == kForever)) {
    return std::nullopt;
  }
  return w;
}

/// The latest end among the reservations seen so far, excluding one agent: the best two
/// of distinct agents are enough.
class LatestEnds {
 public:
  void add(const AgentId& agent, TimeNs end) {
    if (agent == first_agent_) {
      first_end_ = std::max(first_end_, end);
    } else if (end > first_end_) {
      second_agent_ = std::exchange(first_agent_, agent);
      second_end_ = std::exchange(first_end_, end);
    } else if (end > second_end_) {
      second_agent_ = agent;
      second_end_ = end;
    }
  }
  TimeNs excluding(const AgentId& agent) const {
    return agent == first_agent_ ? second_end_ : first_end_;
  }

 private:
  static constexpr TimeNs kNone = std::numeric_limits<TimeNs>::min();
  AgentId first_agent_, second_agent_;
  TimeNs first_end_ = kNone, second_end_ = kNone;
};

/// The route's step on `entity`: its first real reservation there, else its first shadow.
std::optional<std::uint32_t> step_on(const Timeline& timeline, EntityIndex entity,
                                     const AgentId& agent, RouteId route) {
  std::optional<std::uint32_t> real, shadow;
  for (const Reservation& r : timeline.reservations) {
    if (r.agent != agent || r.route != route) continue;
    auto& slot = r.origin == entity ? real : shadow;
    if (!slot || r.step < *slot) slot = r.step;
  }
  return real ? real : shadow;
}

}  // namespace

Result<DelayReport> TimelineSet::delay(const AgentId& agent, RouteId route, EntityIndex entity,
                                       DurationNs by) {
  const std::string what = "delay of agent " + agent + " route " + std::to_string(route) +
                           " on entity " + std::to_string(entity);
  if (agent.empty()) return fail(ErrorCode::invalid_argument, "delay: empty agent id");
  if (by <= 0) {
    return fail(ErrorCode::invalid_argument,
                what + ": the delay must be positive, got " + std::to_string(by) + " ns");
  }
  if (!owns(entity)) return fail(ErrorCode::not_found, what + ": entity not owned by this set");
  const std::optional<std::uint32_t> delayed_step = step_on(timelines_[entity], entity, agent, route);
  if (!delayed_step) {
    return fail(ErrorCode::not_found, what + ": the route has no reservation there");
  }

  // Where each route has reservations, to revisit them when its levels rise.
  std::map<RouteKey, std::set<EntityIndex>> entities_of;
  for (EntityIndex x = 0; x < timelines_.size(); ++x) {
    for (const Reservation& r : timelines_[x].reservations) entities_of[key_of(r)].insert(x);
  }

  const RouteKey delayed{agent, route};
  std::map<RouteKey, RouteLevels> levels;
  levels[delayed].raise(std::uint64_t{*delayed_step} + 1, by);
  std::deque<EntityIndex> work(entities_of[delayed].begin(), entities_of[delayed].end());
  std::vector<bool> queued(timelines_.size(), false);
  for (EntityIndex x : work) queued[x] = true;
  const RouteLevels unmoved;
  const auto levels_of = [&](const Reservation& r) -> const RouteLevels& {
    const auto found = levels.find(key_of(r));
    return found == levels.end() ? unmoved : found->second;
  };

  std::vector<std::pair<const Reservation*, TimeNs>> seen_shadows;  // reused per timeline
  while (!work.empty()) {
    const EntityIndex x = work.front();
    work.pop_front();
    queued[x] = false;
    // Over the reservations before the current one, in the original order: a real one
    // (origin x) conflicts with everything on x, a shadow with the real ones and with the
    // shadows whose origins conflict with its own (I1); others do not push it.
    LatestEnds seen, seen_real;
    seen_shadows.clear();
    for (const Reservation& r : timelines_[x].reservations) {
      TimeNs blocker_end = r.origin == x ? seen.excluding(r.agent) : seen_real.excluding(r.agent);
      if (r.origin != x) {
        for (const auto& [shadow, end] : seen_shadows) {
          if (end > blocker_end && shadow->agent != r.agent &&
              Impl::origins_conflict(*this, shadow->origin, r.origin)) {
            blocker_end = end;
          }
        }
      }
      // Saturated at kForever: a delay past the end of time is refused below (moved_window).
      if (blocker_end > shifted(r.window.start, levels_of(r).at(r.step)) &&
          levels[key_of(r)].raise(r.step, blocker_end - r.window.start)) {
        for (EntityIndex y : entities_of[key_of(r)]) {
          if (!queued[y]) {
            queued[y] = true;
            work.push_back(y);
          }
        }
      }
      const RouteLevels& mine = levels_of(r);
      const TimeNs end = r.window.end == kForever ? kForever : shifted(r.window.end, mine.at(std::uint64_t{r.step} + 1));
      seen.add(r.agent, end);
      if (r.origin == x) {
        seen_real.add(r.agent, end);
      } else {
        seen_shadows.emplace_back(&r, end);
      }
    }
  }

  // Compute every new window before changing anything.
  std::vector<std::pair<Reservation*, Interval>> moves;
  for (auto& [route_key, route_levels] : levels) {
    for (EntityIndex x : entities_of[route_key]) {
      for (Reservation& r : timelines_[x].reservations) {
        if (key_of(r) != route_key) continue;
        const std::optional<Interval> w = moved_window(r, route_levels);
        if (!w) {
          return fail(ErrorCode::invalid_argument,
                      what + ": would move agent " + r.agent + "'s reservation on entity " +
                          std::to_string(x) + " past the end of time");
        }
        if (*w != r.window) moves.emplace_back(&r, *w);
      }
    }
  }

  using MovedKey = std::tuple<EntityIndex, AgentId, RouteId, std::uint32_t, EntityIndex>;
  std::set<MovedKey> moved;
  TouchedSet touched;
  for (auto& [r, w] : moves) {
    r->window = w;
    moved.emplace(r->entity, r->agent, r->route, r->step, r->origin);
    touched.insert(r->entity);
  }
  DelayReport report;
  for (EntityIndex x : touched) {
    Timeline& t = timelines_[x];
    Impl::sort_reservations(t);
    for (const Reservation& r : t.reservations) {
      if (!moved.contains({r.entity, r.agent, r.route, r.step, r.origin})) continue;
      if (std::any_of(t.locks.begin(), t.locks.end(),
                      [&](const Lock& lock) { return lock.window.overlaps(r.window); })) {
        report.hit_locks.push_back(r);
      }
    }
  }
  Impl::bump_versions(*this, touched);

  const auto shift_of = [](const RouteKey& key, const RouteLevels& route_levels) {
    return Shift{key.first, key.second, route_levels.first_moved_step(), route_levels.largest()};
  };
  report.shifts.push_back(shift_of(delayed, levels[delayed]));
  for (const auto& [route_key, route_levels] : levels) {
    if (route_key != delayed) report.shifts.push_back(shift_of(route_key, route_levels));
  }
  return report;
}

}  // namespace drover::topology
