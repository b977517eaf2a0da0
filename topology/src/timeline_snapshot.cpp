// TimelineSet::snapshot and TimelineSet::restore: the committed state a topology agent
// journals after each operation, and the set rebuilt from it when the agent restarts.
// Presumed abort: prepared holds and waiting allocation requests are not part of a
// snapshot, so a restart drops them (their requesters time out and ask again).
// restore validates everything before it builds anything: an inconsistent snapshot (a
// damaged or foreign journal) is an error, never a set that breaks I1-I4.

#include <algorithm>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include "drover/topology/timeline.hpp"
#include "timeline_impl.hpp"

namespace drover::topology {
namespace {

std::string describe(const Interval& w) {
  return "[" + std::to_string(w.start) + ", " +
         (w.end == kForever ? std::string("forever") : std::to_string(w.end)) + ")";
}

std::string describe(const Reservation& r) {
  return "reservation " + r.agent + "/route " + std::to_string(r.route) + "/step " +
         std::to_string(r.step) + (r.shadow() ? " (shadow of " + std::to_string(r.origin) + ")" : "") +
         " " + describe(r.window);
}

bool has_uncommitted(const Timeline& t) {
  return !t.waiting.empty() || std::any_of(t.reservations.begin(), t.reservations.end(),
                                           [](const Reservation& r) { return r.prepared; });
}

bool lock_order(const Lock& a, const Lock& b) {
  return std::tie(a.window.start, a.id) < std::tie(b.window.start, b.id);
}

/// Every consistency rule of restore (see its contract), over the conflict sets and owned
/// flags of the set being rebuilt.
class SnapshotCheck {
 public:
  SnapshotCheck(const std::vector<std::vector<EntityIndex>>& conflicts,
                const std::vector<bool>& owned, const TimelineSnapshot& snapshot)
      : conflicts_(conflicts), owned_(owned), snapshot_(snapshot) {}

  Status run() {
    if (snapshot_.next_lock_id == 0 || snapshot_.next_prepare_id == 0) {
      return error("next_lock_id and next_prepare_id must be at least 1");
    }
    for (const EntitySnapshot& es : snapshot_.entities) {
      if (es.entity >= conflicts_.size()) {
        return error("entity " + std::to_string(es.entity) + " is out of range (the topology has " +
                     std::to_string(conflicts_.size()) + " entities)");
      }
      if (!owned_[es.entity]) {
        return error("entity " + std::to_string(es.entity) + " is not owned by this set");
      }
      if (by_entity_.contains(es.entity)) {
        return error("entity " + std::to_string(es.entity) + " is given twice");
      }
      by_entity_.emplace(es.entity, &es);
      if (Status ok = check_reservations(es); !ok) return ok;
      if (Status ok = check_locks(es); !ok) return ok;
    }
    for (const EntitySnapshot& es : snapshot_.entities) {
      if (Status ok = check_shadows(es); !ok) return ok;
      if (Status ok = check_holding(es); !ok) return ok;
    }
    return {};
  }

 private:
  /// (timeline, agent, route, step): a timeline has at most one item per route step.
  using StepKey = std::tuple<EntityIndex, AgentId, RouteId, std::uint32_t>;

  static Status error(const std::string& message) {
    return fail(ErrorCode::invalid_argument, "restore: " + message);
  }
  static Status error(const EntitySnapshot& es, const std::string& message) {
    return error("entity " + std::to_string(es.entity) + ": " + message);
  }

  bool conflict(EntityIndex origin, EntityIndex entity) const {
    const auto& set = conflicts_[origin];
    return std::binary_search(set.begin(), set.end(), entity);
  }
  bool owns(EntityIndex entity) const { return entity < owned_.size() && owned_[entity]; }

  /// Each item well formed and on this timeline; no step twice; I1 on the timeline.
  Status check_reservations(const EntitySnapshot& es) {
    for (const Reservation& r : es.reservations) {
      const std::string what = describe(r);
      if (r.agent.empty()) return error(es, what + ": empty agent id");
      if (r.prepared) return error(es, what + ": prepared (a snapshot holds committed ones only)");
      if (!r.window.valid()) return error(es, what + ": empty or reversed window");
      if (r.entity != es.entity) {
        return error(es, what + ": names entity " + std::to_string(r.entity) + " as its timeline");
      }
      if (r.origin >= conflicts_.size()) {
        return error(es, what + ": origin " + std::to_string(r.origin) + " is out of range");
      }
      if (r.shadow() && !conflict(r.origin, r.entity)) {
        return error(es, what + ": entity " + std::to_string(r.origin) +
                             " does not conflict with this one");
      }
      if (!steps_.emplace(StepKey{r.entity, r.agent, r.route, r.step}, &r).second) {
        return error(es, what + ": its route step is on this timeline twice");
      }
    }
    // I1: in start order, each item must start after every item before it of another
    // agent whose origin conflicts with its own (a real item's origin conflicts with all).
    std::vector<const Reservation*> order;
    for (const Reservation& r : es.reservations) order.push_back(&r);
    std::sort(order.begin(), order.end(), [](const Reservation* a, const Reservation* b) {
      return a->window.start < b->window.start;  // same-start items of two agents overlap
    });
    for (std::size_t i = 0; i < order.size(); ++i) {
      for (std::size_t j = 0; j < i; ++j) {
        const Reservation* before = order[j];
        const Reservation* r = order[i];
        if (before->agent != r->agent && r->window.start < before->window.end &&
            (before->origin == r->origin || conflict(before->origin, r->origin))) {
          return error(es, describe(*r) + " overlaps " + describe(*before) + " (I1)");
        }
      }
    }
    return {};
  }

  Status check_locks(const EntitySnapshot& es) {
    for (const Lock& lock : es.locks) {
      const std::string what = "lock " + std::to_string(lock.id);
      if (lock.id == 0 || lock.id >= snapshot_.next_lock_id) {
        return error(es, what + ": the id is not in [1, next_lock_id " +
                             std::to_string(snapshot_.next_lock_id) + ")");
      }
      if (!lock_ids_.insert(lock.id).second) return error(es, what + ": the id is used twice");
      if (lock.entity != es.entity) {
        return error(es, what + ": names entity " + std::to_string(lock.entity));
      }
      if (!lock.window.valid()) {
        return error(es, what + ": empty or reversed window " + describe(lock.window));
      }
      if (lock.operator_id.empty()) return error(es, what + ": empty operator id");
    }
    return {};
  }

  /// The item of (agent, route, step) on `entity`, if the snapshot has one.
  const Reservation* find(EntityIndex entity, const Reservation& like) const {
    const auto found = steps_.find(StepKey{entity, like.agent, like.route, like.step});
    return found == steps_.end() ? nullptr : found->second;
  }

  /// Real reservations and their shadows match wherever both ends are owned.
  Status check_shadows(const EntitySnapshot& es) const {
    for (const Reservation& r : es.reservations) {
      if (!r.shadow()) {
        for (EntityIndex f : conflicts_[r.origin]) {
          if (!owns(f)) continue;
          const Reservation* shadow = find(f, r);
          if (!shadow || shadow->origin != r.origin || shadow->window != r.window) {
            return error(es, describe(r) + " has no shadow with its window on entity " +
                                 std::to_string(f));
          }
        }
      } else if (owns(r.origin)) {
        const Reservation* real = find(r.origin, r);
        if (!real || real->shadow() || real->window != r.window) {
          return error(es, describe(r) + " has no real reservation with its window on entity " +
                               std::to_string(r.origin));
        }
      }
    }
    return {};
  }

  /// A holder holds its committed real reservation, nobody else's comes before it (I2), and
  /// no other agent holds a conflicting entity (I1).
  Status check_holding(const EntitySnapshot& es) const {
    if (!es.holding) return {};
    const Holding& h = es.holding.value();
    const std::string what = "holder " + h.agent + " (route " + std::to_string(h.step.route) +
                             ", step " + std::to_string(h.step.step) + ")";
    if (h.agent.empty()) return error(es, "empty holder id");
    Reservation like;
    like.agent = h.agent;
    like.route = h.step.route;
    like.step = h.step.step;
    const Reservation* held = find(es.entity, like);
    if (!held || held->shadow()) {
      return error(es, what + " has no real reservation of that step here");
    }
    for (const Reservation& r : es.reservations) {
      if (r.agent != h.agent && r.window.start < held->window.start) {
        return error(es, what + " has " + describe(r) + " before its own (I2)");
      }
    }
    for (EntityIndex f : conflicts_[es.entity]) {
      const auto other = by_entity_.find(f);
      if (other != by_entity_.end() && other->second->holding &&
          other->second->holding->agent != h.agent) {
        return error(es, what + " and holder " + other->second->holding->agent +
                             " of conflicting entity " + std::to_string(f));
      }
    }
    return {};
  }

  const std::vector<std::vector<EntityIndex>>& conflicts_;
  const std::vector<bool>& owned_;
  const TimelineSnapshot& snapshot_;
  std::map<EntityIndex, const EntitySnapshot*> by_entity_;
  std::map<StepKey, const Reservation*> steps_;
  std::set<LockId> lock_ids_;
};

}  // namespace

TimelineSnapshot TimelineSet::snapshot() const {
  std::vector<EntityIndex> entities;
  for (EntityIndex e = 0; e < timelines_.size(); ++e) {
    const Timeline& t = timelines_[e];
    if (owns(e) && (t.version > 0 || !t.reservations.empty() || !t.locks.empty() || t.holder)) {
      entities.push_back(e);
    }
  }
  return snapshot(entities);
}

TimelineSnapshot TimelineSet::snapshot(const std::vector<EntityIndex>& entities) const {
  const std::set<EntityIndex> wanted(entities.begin(), entities.end());
  TimelineSnapshot s;
  s.next_lock_id = next_lock_id_;
  s.next_prepare_id = next_prepare_id_;
  for (EntityIndex e : wanted) {
    if (!owns(e)) continue;
    const Timeline& t = timelines_[e];
    EntitySnapshot es;
    es.entity = e;
    es.version = t.version + (has_uncommitted(t) ? 1 : 0);
    std::copy_if(t.reservations.begin(), t.reservations.end(), std::back_inserter(es.reservations),
                 [](const Reservation& r) { return !r.prepared; });
    es.locks = t.locks;
    if (t.holder) es.holding = Holding{*t.holder, *held_[e]};
    s.entities.push_back(std::move(es));
  }
  return s;
}

Result<TimelineSet> TimelineSet::restore(std::vector<std::vector<EntityIndex>> conflict_sets,
                                         std::vector<bool> owned,
                                         const TimelineSnapshot& snapshot) {
  TimelineSet set(std::move(conflict_sets), std::move(owned));
  if (Status ok = SnapshotCheck(set.conflict_sets_, set.owned_, snapshot).run(); !ok) {
    return unexpected(std::move(ok).error());
  }
  for (const EntitySnapshot& es : snapshot.entities) {
    Timeline& t = set.timelines_[es.entity];
    t.version = es.version;
    t.reservations = es.reservations;
    Impl::sort_reservations(t);
    t.locks = es.locks;
    std::sort(t.locks.begin(), t.locks.end(), lock_order);
    for (const Lock& lock : t.locks) set.lock_entities_.emplace(lock.id, es.entity);
    set.lock_count_ += t.locks.size();
    if (es.holding) {
      t.holder = es.holding->agent;
      set.held_[es.entity] = es.holding->step;
    }
  }
  Impl::revise_all(set);  // after the timelines are filled in
  set.next_lock_id_ = snapshot.next_lock_id;
  set.next_prepare_id_ = snapshot.next_prepare_id;
  return set;
}

}  // namespace drover::topology
