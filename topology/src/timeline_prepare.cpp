// TimelineSet: two-phase reservation (prepare / commit / abort / expire) and reserve.
// prepare validates everything before it changes anything, so a rejection changes nothing.

#include <algorithm>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "drover/topology/timeline.hpp"
#include "timeline_impl.hpp"

namespace drover::topology {
namespace {

std::string window_text(const Interval& w) {
  return "[" + std::to_string(w.start) + ", " +
         (w.end == kForever ? std::string("forever") : std::to_string(w.end)) + ")";
}

std::string item_text(std::size_t index, const Reservation& item) {
  return "item " + std::to_string(index) + " (entity " + std::to_string(item.entity) +
         ", step " + std::to_string(item.step) + ", " + window_text(item.window) + ")";
}

std::string owner_text(const Reservation& r) {
  return "agent " + r.agent + " route " + std::to_string(r.route) + " step " +
         std::to_string(r.step) + " " + window_text(r.window);
}

/// The checks of prepare that need no timeline: well-formed, one route, consistent steps.
Status check_well_formed(const std::vector<Reservation>& items, std::size_t entity_count,
                         const std::function<bool(EntityIndex, EntityIndex)>& conflicts) {
  if (items.empty()) return fail(ErrorCode::invalid_argument, "no items");
  const Reservation& first = items.front();
  if (items.size() > std::numeric_limits<std::uint32_t>::max()) {
    return fail(ErrorCode::invalid_argument, "more than 2^32 - 1 items");
  }
  // Per item, the first item of its step: from (step, index) pairs packed in one integer,
  // sorted only when the steps are out of order (expand makes them in order). Sorting
  // indices by a lookup into the items, twice, was a seventh of reserve's instructions
  // (bench plan, random N = 200).
  std::vector<std::uint64_t> keys(items.size());
  const auto pack = [](std::uint32_t high, std::uint64_t low) {
    return std::uint64_t{high} << 32 | low;
  };
  for (std::size_t i = 0; i < items.size(); ++i) keys[i] = pack(items[i].step, i);
  if (!std::is_sorted(keys.begin(), keys.end())) std::sort(keys.begin(), keys.end());
  std::vector<std::uint32_t> first_of_step(items.size());
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const auto index = static_cast<std::uint32_t>(keys[k]);
    const bool starts = k == 0 || keys[k - 1] >> 32 != keys[k] >> 32;
    first_of_step[index] = starts ? index : first_of_step[static_cast<std::uint32_t>(keys[k - 1])];
  }
  // Whether an earlier item has the item's entity and step: worked out item by item only
  // when some pair repeats, which a sort of the packed pairs tells.
  for (std::size_t i = 0; i < items.size(); ++i) keys[i] = pack(items[i].entity, items[i].step);
  std::sort(keys.begin(), keys.end());
  std::vector<bool> repeated;
  if (std::adjacent_find(keys.begin(), keys.end()) != keys.end()) {
    repeated.resize(items.size());
    std::set<std::uint64_t> seen;
    for (std::size_t i = 0; i < items.size(); ++i) {
      repeated[i] = !seen.insert(pack(items[i].entity, items[i].step)).second;
    }
  }
  for (std::size_t i = 0; i < items.size(); ++i) {
    const Reservation& item = items[i];
    // Built only for an error: a route has hundreds of items and most prepares succeed.
    const auto where = [&] { return item_text(i, item); };
    if (item.agent.empty()) {
      return fail(ErrorCode::invalid_argument, where() + ": empty agent id");
    }
    if (item.agent != first.agent || item.route != first.route) {
      return fail(ErrorCode::invalid_argument,
                  where() + ": belongs to agent " + item.agent + " route " +
                      std::to_string(item.route) + ", item 0 to agent " + first.agent +
                      " route " + std::to_string(first.route) + " (one route per prepare)");
    }
    if (!item.window.valid()) {
      return fail(ErrorCode::invalid_argument, where() + ": empty or reversed window");
    }
    if (item.origin >= entity_count) {
      return fail(ErrorCode::invalid_argument,
                  where() + ": origin " + std::to_string(item.origin) + " is out of range");
    }
    if (item.entity < entity_count && item.entity != item.origin &&
        !conflicts(item.origin, item.entity)) {
      return fail(ErrorCode::invalid_argument,
                  where() + ": a shadow of entity " + std::to_string(item.origin) +
                      ", which does not conflict with it");
    }
    const Reservation& same_step = items[first_of_step[i]];
    if (same_step.origin != item.origin || same_step.window != item.window) {
      return fail(ErrorCode::invalid_argument,
                  where() + ": its step has origin " + std::to_string(same_step.origin) + " " +
                      window_text(same_step.window) + " in item " +
                      std::to_string(first_of_step[i]));
    }
    if (!repeated.empty() && repeated[i]) {
      return fail(ErrorCode::invalid_argument, where() + ": appears twice");
    }
  }
  return {};
}

}  // namespace

Status TimelineSet::Impl::admit(const TimelineSet& set, const std::vector<Reservation>& items,
                                const std::vector<ExpectedVersion>& expected,
                                const std::string& op) {
  if (auto well_formed = check_well_formed(
          items, set.entity_count(),
          [&set](EntityIndex origin, EntityIndex entity) {
            return in_conflict_set(set, origin, entity);
          });
      !well_formed) {
    return unexpected(Error{ErrorCode::invalid_argument, op + ": " + well_formed.error().message});
  }
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (!set.owns(items[i].entity)) {
      return fail(ErrorCode::not_found,
                  op + ": " + item_text(i, items[i]) + ": entity not owned by this set");
    }
  }
  for (const ExpectedVersion& ev : expected) {
    if (!set.owns(ev.entity)) {
      return fail(ErrorCode::not_found, op + ": expected version of entity " +
                                            std::to_string(ev.entity) +
                                            ", which this set does not own");
    }
  }
  // Every step whole, as expand() writes it on owned entities: a real item without its
  // shadows would let another agent reserve a conflicting entity at the same time (I1), and
  // the journal of such a state is refused on restore. check_well_formed saw to it that
  // each item is the origin or a member of its conflict set, once; so counts suffice.
  std::map<std::uint32_t, std::pair<EntityIndex, std::size_t>> steps;  // step -> origin, items
  for (const Reservation& item : items) {
    auto& [origin, count] = steps.try_emplace(item.step, item.origin, 0).first->second;
    ++count;
  }
  for (const auto& [step, found] : steps) {
    const auto& [origin, count] = found;
    const auto& conflicts = set.conflict_sets_[origin];
    const std::size_t owned = (set.owns(origin) ? 1 : 0) +
                              static_cast<std::size_t>(std::count_if(conflicts.begin(), conflicts.end(),
                                                                     [&set](EntityIndex e) { return set.owns(e); }));
    if (count != owned) {
      return fail(ErrorCode::invalid_argument,
                  op + ": step " + std::to_string(step) + " (entity " + std::to_string(origin) + ") has " +
                      std::to_string(count) + " item(s) here, not " + std::to_string(owned) +
                      ": the real reservation where its entity is owned and a shadow on every owned "
                      "member of its conflict set, as expand() writes them");
    }
  }
  for (const ExpectedVersion& ev : expected) {
    if (set.version(ev.entity) != ev.version) {
      return fail(ErrorCode::conflict,
                  op + ": entity " + std::to_string(ev.entity) + " is at version " +
                      std::to_string(set.version(ev.entity)) + ", the plan expected version " +
                      std::to_string(ev.version));
    }
  }
  const std::span<const EntityIndex> agent_entities = set.reserved_entities(items.front().agent);
  for (std::size_t i = 0; i < items.size(); ++i) {
    const Reservation& item = items[i];
    // Most items of a planned route lie in a window a newcomer sees: then none of the
    // checks below can fail, and the reservations (72 bytes each, hundreds per route) need
    // not be read (bench plan, random N = 200: they were a third of reserve's memory
    // traffic, which left the planner's data out of the cache).
    if (clear_for_newcomer(set, item, agent_entities)) continue;
    const Timeline& t = set.timelines_[item.entity];
    const auto where = [&] { return op + ": " + item_text(i, item); };  // only for an error
    for (const Reservation& r : t.reservations) {
      // The cheap tests first: most reservations of a timeline are another agent's, at
      // another time.
      if (r.route == item.route && r.step == item.step && r.agent == item.agent) {
        return fail(ErrorCode::conflict, where() + ": the step is already reserved here");
      }
      const bool overlaps = r.window.overlaps(item.window);
      const bool before_held = !overlaps && item.window.start < r.window.start &&
                               r.origin < set.held_.size() && set.held_[r.origin] &&
                               is_held(set, r);
      if (!overlaps && !before_held) continue;
      if (r.agent == item.agent) continue;  // an agent's own items never block it
      // Shadows of two entities that do not conflict may share a timeline at any time:
      // they stand for reservations elsewhere that I1 lets overlap.
      if (!origins_conflict(set, r.origin, item.origin)) continue;
      if (overlaps) return fail(ErrorCode::conflict, where() + ": overlaps " + owner_text(r));
      return fail(ErrorCode::conflict,
                  where() + ": would come before the allocated " + owner_text(r));
    }
    for (const Lock& lock : t.locks) {
      if (lock.window.overlaps(item.window)) {
        return fail(ErrorCode::conflict, where() + ": overlaps lock " + std::to_string(lock.id) +
                                             " " + window_text(lock.window) + " (" +
                                             lock.reason + ")");
      }
    }
  }
  return {};
}

/// See insert.
constexpr std::size_t kFirstReservations = 8;

void TimelineSet::Impl::insert(TimelineSet& set, const std::vector<Reservation>& items,
                               bool prepared, TouchedSet& touched) {
  // Recorded at once at the end: one by one into the sorted set, the hundreds of entities
  // of a route cost reserve 2 % more instructions.
  std::vector<EntityIndex> entities;
  entities.reserve(items.size());
  const std::uint32_t agent = agent_number(set, items.front().agent);  // one agent (admit)
  for (const Reservation& item : items) {
    // Each item goes where timeline order puts it (a route adds one or a few items to a
    // timeline of many: cheaper than sorting the timeline again).
    std::vector<Reservation>& timeline = set.timelines_[item.entity].reservations;
    // A timeline that gets reservations gets many (every route over the entity or its
    // conflict set): room for 8 at once spares the moves of growing through 1, 2 and 4.
    if (timeline.capacity() == 0) timeline.reserve(kFirstReservations);
    const auto at = std::upper_bound(timeline.begin(), timeline.end(), item, timeline_order);
    Reservation& added = *timeline.insert(at, item);
    added.prepared = prepared;
    entities.push_back(item.entity);
    // The newcomer's windows lose the item's window, and its agent is among those with a
    // reservation there (add_reservers, below): what revise's sweep would find, without
    // reading the reservations again. Unless the item is held (never, after admit: its
    // step would be reserved here already), which blocks everything before it too.
    if (is_held(set, added)) {
      revise(set, item.entity, set.revisions_.of[item.entity]);
    } else {
      cut_window(set.newcomers_.of[item.entity], item.window);
    }
  }
  add_reservers(set, agent, entities);
  touched.insert(entities.begin(), entities.end());
}

Result<PrepareId> TimelineSet::prepare(const std::vector<Reservation>& items,
                                       const std::vector<ExpectedVersion>& expected,
                                       TimeNs expires_at) {
  if (Status admitted = Impl::admit(*this, items, expected, "prepare"); !admitted) {
    return unexpected(std::move(admitted).error());
  }
  PreparedSet held{items.front().agent, items.front().route, expires_at, {}};
  for (const Reservation& item : items) {
    held.items.push_back(ItemKey{item.entity, item.step, item.origin});
  }
  TouchedSet touched;
  Impl::insert(*this, items, true, touched);
  Impl::bump_versions(*this, touched, Impl::Windows::updated);
  const PrepareId id = next_prepare_id_++;
  prepared_.emplace(id, std::move(held));
  return id;
}

Status TimelineSet::commit(PrepareId id) {
  const auto found = prepared_.find(id);
  if (found == prepared_.end()) {
    return fail(ErrorCode::not_found,
                "commit: prepared set " + std::to_string(id) + " is unknown, aborted or expired");
  }
  const PreparedSet& held = found->second;
  TouchedSet touched;
  for (const ItemKey& key : held.items) {
    for (Reservation& r : timelines_[key.entity].reservations) {
      if (r.prepared && r.agent == held.agent && r.route == held.route && r.step == key.step &&
          r.origin == key.origin) {
        r.prepared = false;
      }
    }
    touched.insert(key.entity);
  }
  prepared_.erase(found);
  // The agent's own new reservation may come before everyone else's where it waits.
  Impl::keep_grants(*this, Impl::grant_waiting(*this, TouchedSet(touched), touched));
  // A prepared reservation blocks others as a committed one does, so the free windows stay
  // (a grant above revised those it changed): no entity's windows are recomputed.
  Impl::bump_versions(*this, touched, Impl::Windows::unchanged);
  return {};
}

void TimelineSet::Impl::keep_grants(TimelineSet& set, const std::vector<Grant>& grants) {
  set.pending_grants_.insert(set.pending_grants_.end(), grants.begin(), grants.end());
}

void TimelineSet::Impl::drop_prepared(TimelineSet& set, PrepareId id, TouchedSet& touched) {
  const auto found = set.prepared_.find(id);
  const PreparedSet& held = found->second;
  TouchedSet dropped;
  for (const ItemKey& key : held.items) {
    std::erase_if(set.timelines_[key.entity].reservations, [&](const Reservation& r) {
      return r.prepared && r.agent == held.agent && r.route == held.route &&
             r.step == key.step && r.origin == key.origin;
    });
    dropped.insert(key.entity);
  }
  set.prepared_.erase(found);
  touched.insert(dropped.begin(), dropped.end());
  keep_grants(set, grant_waiting(set, dropped, touched));
}

Status TimelineSet::abort(PrepareId id) {
  if (!prepared_.contains(id)) {
    return fail(ErrorCode::not_found,
                "abort: prepared set " + std::to_string(id) + " is unknown, committed or expired");
  }
  TouchedSet touched;
  Impl::drop_prepared(*this, id, touched);
  Impl::bump_versions(*this, touched);
  return {};
}

std::vector<PrepareId> TimelineSet::expire(TimeNs now) {
  std::vector<PrepareId> expired;
  for (const auto& [id, held] : prepared_) {
    if (held.expires_at <= now) expired.push_back(id);
  }
  TouchedSet touched;
  for (PrepareId id : expired) Impl::drop_prepared(*this, id, touched);
  Impl::bump_versions(*this, touched);
  return expired;
}

std::vector<Grant> TimelineSet::take_grants() { return std::exchange(pending_grants_, {}); }

Status TimelineSet::reserve(const AgentId& agent, RouteId route,
                            const std::vector<RouteStep>& steps) {
  if (steps.empty()) return fail(ErrorCode::invalid_argument, "reserve: the route has no steps");
  if (agent.empty()) return fail(ErrorCode::invalid_argument, "reserve: empty agent id");
  for (std::size_t i = 0; i < steps.size(); ++i) {
    if (!steps[i].window.valid()) {
      return fail(ErrorCode::invalid_argument,
                  "reserve: step " + std::to_string(i) + " on entity " +
                      std::to_string(steps[i].entity) + " has an empty or reversed window " +
                      window_text(steps[i].window));
    }
  }
  for (std::size_t i = 0; i < steps.size(); ++i) {
    if (!owns(steps[i].entity)) {
      return fail(ErrorCode::not_found, "reserve: step " + std::to_string(i) + " is on entity " +
                                            std::to_string(steps[i].entity) +
                                            ", which this set does not own");
    }
  }
  std::vector<Reservation> items = expand(agent, route, steps);
  std::erase_if(items, [this](const Reservation& r) { return !owns(r.entity); });
  if (Status admitted = Impl::admit(*this, items, {}, "reserve"); !admitted) return admitted;
  // One change, as if prepared and committed at once.
  TouchedSet touched;
  Impl::insert(*this, items, false, touched);
  // A grant revises the windows it changes.
  Impl::keep_grants(*this, Impl::grant_waiting(*this, TouchedSet(touched), touched));
  Impl::bump_versions(*this, touched, Impl::Windows::updated);
  return {};
}

}  // namespace drover::topology
