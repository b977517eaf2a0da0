// Random TimelineSet operations for persistence tests; see the header.

#include "tests/topology/timeline_workload.hpp"

#include <algorithm>
#include <utility>

namespace drover::topology::test {
namespace {
constexpr TimeNs kHorizon = 300;

/// Would the agent's allocation request on this timeline be granted now (I2)?
bool grantable(const Timeline& t, const AgentId& agent) {
  if (t.holder) return t.holder == agent;
  const auto mine = std::find_if(t.reservations.begin(), t.reservations.end(), [&](const Reservation& r) {
    return r.agent == agent && !r.shadow() && !r.prepared;
  });
  return mine != t.reservations.end() &&
         std::none_of(t.reservations.begin(), t.reservations.end(), [&](const Reservation& r) {
           return r.agent != agent && r.window.start < mine->window.start;
         });
}
}  // namespace

std::vector<std::vector<EntityIndex>> random_conflicts(std::uint64_t seed, std::size_t count,
                                                       double density) {
  std::mt19937_64 rng(seed);
  std::bernoulli_distribution conflict(density);
  std::vector<std::vector<EntityIndex>> sets(count);
  for (EntityIndex a = 0; a < count; ++a) {
    for (EntityIndex b = a + 1; b < count; ++b) {
      if (conflict(rng)) {
        sets[a].push_back(b);
        sets[b].push_back(a);
      }
    }
  }
  for (auto& set : sets) std::sort(set.begin(), set.end());
  return sets;
}

TimelineWorkload::TimelineWorkload(std::uint64_t seed,
                                   std::vector<std::vector<EntityIndex>> conflicts,
                                   std::vector<bool> owned, bool queue)
    : rng_(seed), conflicts_(std::move(conflicts)), queue_(queue) {
  for (EntityIndex e = 0; e < conflicts_.size(); ++e) {
    if (owned.empty() || (e < owned.size() && owned[e])) owned_.push_back(e);
  }
}

EntityIndex TimelineWorkload::owned_entity() {
  return owned_[static_cast<std::size_t>(uniform(0, static_cast<TimeNs>(owned_.size()) - 1))];
}

EntityIndex TimelineWorkload::any_entity() {
  return static_cast<EntityIndex>(uniform(0, static_cast<TimeNs>(conflicts_.size()) - 1));
}

const Reservation* TimelineWorkload::some_reservation(const TimelineSet& set) {
  std::vector<const Reservation*> all;
  for (EntityIndex e : owned_) {
    for (const Reservation& r : set.timeline(e).reservations) all.push_back(&r);
  }
  if (all.empty()) return nullptr;
  return all[static_cast<std::size_t>(uniform(0, static_cast<TimeNs>(all.size()) - 1))];
}

/// 1-4 steps, each in the first free window of its entity that is long enough (a tiny
/// CARP), consecutive ones overlapping by a clearance; sometimes open-ended.
std::vector<RouteStep> TimelineWorkload::plan(const TimelineSet& set, const AgentId& agent,
                                              bool owned_only) {
  const int length = static_cast<int>(uniform(1, 4));
  TimeNs t = uniform(0, kHorizon);
  std::vector<RouteStep> steps;
  for (int i = 0; i < length; ++i) {
    const EntityIndex entity = owned_only ? owned_entity() : any_entity();
    const DurationNs duration = uniform(2, 30);
    const DurationNs clearance = uniform(0, 2);
    TimeNs start = t;
    if (set.owns(entity)) {
      const auto free = set.free_windows(entity, agent, t, kForever);
      const auto fits = std::find_if(free.begin(), free.end(), [&](const Interval& w) {
        return w.end == kForever || w.end - w.start >= duration;
      });
      if (fits == free.end()) break;
      start = fits->start;
      if (!steps.empty()) {
        steps.back().window.end = std::max(steps.back().window.end, start + clearance);
      }
    }
    steps.push_back(RouteStep{entity, Interval{start, start + duration}});
    t = start + duration - clearance;
  }
  if (!steps.empty() && chance(0.05)) steps.back().window.end = kForever;
  return steps;
}

std::string TimelineWorkload::reserve(TimelineSet& set) {
  const AgentId& agent = agents_[static_cast<std::size_t>(uniform(0, 2))];
  const RouteId route = next_route_++;
  const auto steps = plan(set, agent, true);
  if (steps.empty()) return "reserve: nothing free";
  const Status done = set.reserve(agent, route, steps);
  return "reserve " + agent + " route " + std::to_string(route) + (done ? "" : ": rejected");
}

/// A prepare left open; on a partition (`neighbour`) a route over any entities, of which
/// the owned items are prepared and committed at once, as a neighbour's route writes them.
std::string TimelineWorkload::prepare(TimelineSet& set, bool neighbour) {
  const AgentId& agent = agents_[static_cast<std::size_t>(uniform(0, 2))];
  const RouteId route = next_route_++;
  auto items = set.expand(agent, route, plan(set, agent, !neighbour));
  std::erase_if(items, [&](const Reservation& r) { return !set.owns(r.entity); });
  if (items.empty()) return "prepare: nothing owned";
  const auto id = set.prepare(items, {}, uniform(0, 1000));
  if (!id) return "prepare: rejected";
  if (neighbour) {
    (void)set.commit(*id);
    return "neighbour route " + std::to_string(route);
  }
  open_prepares_.push_back(*id);
  return "prepare " + std::to_string(*id);
}

std::string TimelineWorkload::finish_prepare(TimelineSet& set) {
  if (open_prepares_.empty()) return "commit: none open";
  const auto pick = static_cast<std::size_t>(uniform(0, static_cast<TimeNs>(open_prepares_.size()) - 1));
  const PrepareId id = open_prepares_[pick];
  open_prepares_.erase(open_prepares_.begin() + static_cast<std::ptrdiff_t>(pick));
  if (chance(0.7)) return "commit " + std::to_string(id) + (set.commit(id) ? "" : ": gone");
  return "abort " + std::to_string(id) + (set.abort(id) ? "" : ": gone");
}

std::string TimelineWorkload::allocate(TimelineSet& set) {
  const Reservation* r = some_reservation(set);
  if (!r || !set.owns(r->origin)) return "allocate: nothing";
  const AgentId agent = r->agent;
  const EntityIndex entity = r->origin;
  if (!queue_ && !grantable(set.timeline(entity), agent)) return "allocate: would queue";
  const auto got = set.allocate(agent, entity);
  return "allocate " + agent + " " + std::to_string(entity) +
         (!got ? ": rejected" : got->granted ? ": granted" : ": queued");
}

std::string TimelineWorkload::release(TimelineSet& set) {
  std::vector<EntityIndex> held;
  for (EntityIndex e : owned_) {
    if (set.timeline(e).holder) held.push_back(e);
  }
  if (held.empty()) return "release: nothing held";
  const EntityIndex e = held[static_cast<std::size_t>(uniform(0, static_cast<TimeNs>(held.size()) - 1))];
  const AgentId agent = *set.timeline(e).holder;
  (void)set.release(agent, e);
  return "release " + agent + " " + std::to_string(e);
}

std::string TimelineWorkload::cancel(TimelineSet& set) {
  const Reservation* r = some_reservation(set);
  if (!r) return "cancel: nothing";
  const AgentId agent = r->agent;
  const RouteId route = r->route;
  (void)set.cancel_route(agent, route);
  return "cancel " + agent + " route " + std::to_string(route);
}

std::string TimelineWorkload::delay(TimelineSet& set) {
  const Reservation* r = some_reservation(set);
  if (!r) return "delay: nothing";
  const Reservation copy = *r;
  const DurationNs by = uniform(1, 40);
  const auto done = set.delay(copy.agent, copy.route, copy.entity, by);
  return "delay " + copy.agent + " route " + std::to_string(copy.route) + " by " +
         std::to_string(by) + (done ? "" : ": rejected");
}

std::string TimelineWorkload::lock(TimelineSet& set) {
  const EntityIndex entity = owned_entity();
  const TimeNs start = uniform(0, kHorizon);
  const auto got = set.lock(entity, Interval{start, start + uniform(1, 60)}, "operator",
                            "aisle blocked");
  if (!got) return "lock: rejected";
  locks_.push_back(got->id);
  return "lock " + std::to_string(got->id) + " on " + std::to_string(entity);
}

std::string TimelineWorkload::unlock(TimelineSet& set) {
  if (locks_.empty()) return "unlock: none";
  const auto pick = static_cast<std::size_t>(uniform(0, static_cast<TimeNs>(locks_.size()) - 1));
  const LockId id = locks_[pick];
  locks_.erase(locks_.begin() + static_cast<std::ptrdiff_t>(pick));
  return "unlock " + std::to_string(id) + (set.unlock(id) ? "" : ": gone");
}

std::string TimelineWorkload::apply(TimelineSet& set) {
  const bool partition = owned_.size() < conflicts_.size();
  const int what = static_cast<int>(uniform(0, 99));
  std::string done;
  if (what < 22) done = reserve(set);
  else if (what < 30) done = prepare(set, false);
  else if (what < 36) done = partition ? prepare(set, true) : reserve(set);
  else if (what < 44) done = finish_prepare(set);
  else if (what < 47) done = "expire " + std::to_string(set.expire(uniform(0, 1000)).size());
  else if (what < 63) done = allocate(set);
  else if (what < 72) done = release(set);
  else if (what < 80) done = cancel(set);
  else if (what < 88) done = delay(set);
  else if (what < 94) done = lock(set);
  else done = unlock(set);
  (void)set.take_grants();
  return done;
}

}  // namespace drover::topology::test
