// Brute-force reference of TimelineSet semantics and invariant checkers; see the header.
// Deliberately simple: every question is answered by scanning the flat list.

#include "tests/topology/timeline_reference.hpp"

#include <algorithm>
#include <limits>
#include <sstream>
#include <utility>

namespace drover::topology {

void PrintTo(const Interval& w, std::ostream* out) {
  *out << "[" << w.start << ", " << (w.end == kForever ? std::string("forever") : std::to_string(w.end))
       << ")";
}
void PrintTo(const Reservation& r, std::ostream* out) {
  *out << r.agent << "/route " << r.route << "/step " << r.step << " on " << r.entity;
  if (r.shadow()) *out << " (shadow of " << r.origin << ")";
  *out << " ";
  PrintTo(r.window, out);
  if (r.prepared) *out << " prepared";
}
void PrintTo(const Shift& s, std::ostream* out) {
  *out << s.agent << "/route " << s.route << " from step " << s.from_step << " by " << s.by;
}
void PrintTo(const Grant& g, std::ostream* out) { *out << g.agent << " gets " << g.entity; }
void PrintTo(const Timeline& t, std::ostream* out) {
  *out << "{version " << t.version << ", reservations:";
  for (const Reservation& r : t.reservations) {
    *out << " ";
    PrintTo(r, out);
    *out << ";";
  }
  *out << " locks:";
  for (const Lock& l : t.locks) {
    *out << " " << l.id << " ";
    PrintTo(l.window, out);
  }
  *out << " holder: " << t.holder.value_or("-") << " waiting:";
  for (const AgentId& w : t.waiting) *out << " " << w;
  *out << "}";
}

}  // namespace drover::topology

namespace drover::topology::reference {
namespace {

bool timeline_order(const Reservation& a, const Reservation& b) {
  if (a.window.start != b.window.start) return a.window.start < b.window.start;
  if (a.window.end != b.window.end) return a.window.end < b.window.end;
  if (a.agent != b.agent) return a.agent < b.agent;
  if (a.route != b.route) return a.route < b.route;
  if (a.step != b.step) return a.step < b.step;
  return a.origin < b.origin;
}

std::string text(const Reservation& r) {
  std::ostringstream out;
  PrintTo(r, &out);
  return out.str();
}

bool contains(const std::vector<EntityIndex>& set, EntityIndex e) {
  return std::find(set.begin(), set.end(), e) != set.end();
}

/// Whether reservations of two agents standing for entities a and b (their origins) may
/// not overlap (I1): the same entity, or entities whose footprints overlap.
bool origins_conflict(const std::vector<std::vector<EntityIndex>>& conflicts, EntityIndex a,
                      EntityIndex b) {
  return a == b || contains(conflicts[a], b);
}

bool add_overflows(TimeNs a, DurationNs b, TimeNs& out) {
  return __builtin_add_overflow(a, b, &out) || out == kForever;
}

using RouteKey = std::pair<AgentId, RouteId>;

}  // namespace

ReservationKey key_of(const Reservation& r) {
  return {r.entity, r.agent, r.route, r.step, r.origin};
}

ReferenceTimelines::ReferenceTimelines(std::vector<std::vector<EntityIndex>> conflicts)
    : conflicts_(std::move(conflicts)), versions_(conflicts_.size(), 0) {}

template <class F>
auto ReferenceTimelines::versioned(F&& change) {
  std::vector<Timeline> before;
  for (EntityIndex e = 0; e < conflicts_.size(); ++e) before.push_back(timeline(e));
  auto result = change();
  for (EntityIndex e = 0; e < conflicts_.size(); ++e) {
    if (!(timeline(e) == before[e])) ++versions_[e];
  }
  return result;
}

Timeline ReferenceTimelines::timeline(EntityIndex entity) const {
  Timeline t;
  t.version = versions_[entity];
  for (const Item& item : items_) {
    if (item.reservation.entity == entity) t.reservations.push_back(item.reservation);
  }
  std::sort(t.reservations.begin(), t.reservations.end(), timeline_order);
  for (const Lock& lock : locks_) {
    if (lock.entity == entity) t.locks.push_back(lock);
  }
  std::sort(t.locks.begin(), t.locks.end(), [](const Lock& a, const Lock& b) {
    return a.window.start != b.window.start ? a.window.start < b.window.start : a.id < b.id;
  });
  if (auto held = holders_.find(entity); held != holders_.end()) t.holder = held->second.agent;
  if (auto waiting = waiting_.find(entity); waiting != waiting_.end()) t.waiting = waiting->second;
  return t;
}

Snapshot ReferenceTimelines::snapshot() const {
  Snapshot s{conflicts_, {}, holders_};
  for (EntityIndex e = 0; e < conflicts_.size(); ++e) s.timelines.push_back(timeline(e));
  return s;
}

std::vector<Reservation> ReferenceTimelines::all() const {
  std::vector<Reservation> out;
  for (const Item& item : items_) out.push_back(item.reservation);
  return out;
}

bool ReferenceTimelines::held(const Reservation& r) const {
  auto found = holders_.find(r.origin);
  return found != holders_.end() && found->second == HeldStep{r.agent, r.route, r.step};
}

bool ReferenceTimelines::in_conflict_set(EntityIndex origin, EntityIndex entity) const {
  return contains(conflicts_[origin], entity);
}

const Reservation* ReferenceTimelines::first_committed_real(const AgentId& agent,
                                                            EntityIndex entity) const {
  const Reservation* first = nullptr;
  for (const Item& item : items_) {
    const Reservation& r = item.reservation;
    if (r.entity == entity && r.origin == entity && r.agent == agent && item.prepare == 0 &&
        (first == nullptr || timeline_order(r, *first))) {
      first = &r;
    }
  }
  return first;
}

std::size_t ReferenceTimelines::others_before(const AgentId& agent, EntityIndex entity,
                                              TimeNs start) const {
  std::size_t count = 0;
  for (const Item& item : items_) {
    const Reservation& r = item.reservation;
    if (r.entity == entity && r.agent != agent && r.window.start < start) ++count;
  }
  return count;
}

std::vector<Grant> ReferenceTimelines::grant_everywhere() {
  std::vector<Grant> grants;
  for (EntityIndex e = 0; e < conflicts_.size(); ++e) {
    auto& waiting = waiting_[e];
    std::erase_if(waiting, [&](const AgentId& a) { return !first_committed_real(a, e); });
    if (holders_.contains(e)) continue;
    for (std::size_t i = 0; i < waiting.size(); ++i) {
      const Reservation* mine = first_committed_real(waiting[i], e);
      if (others_before(waiting[i], e, mine->window.start) == 0) {
        holders_[e] = HeldStep{waiting[i], mine->route, mine->step};
        grants.push_back(Grant{waiting[i], e});
        waiting.erase(waiting.begin() + static_cast<std::ptrdiff_t>(i));
        break;
      }
    }
  }
  std::erase_if(waiting_, [](const auto& entry) { return entry.second.empty(); });
  return grants;
}

std::vector<Interval> ReferenceTimelines::free_windows(EntityIndex entity, const AgentId& agent,
                                                       TimeNs from, TimeNs until) const {
  if (entity >= conflicts_.size() || from >= until) return {};
  std::vector<Interval> blocked;
  std::vector<EntityIndex> place = conflicts_[entity];
  place.push_back(entity);
  for (const Lock& lock : locks_) {
    if (contains(place, lock.entity)) blocked.push_back(lock.window);
  }
  for (const Item& item : items_) {
    const Reservation& r = item.reservation;
    // A step on `entity` writes on `place`; what is there stands for its origin.
    if (!contains(place, r.entity) || r.agent == agent ||
        !origins_conflict(conflicts_, r.origin, entity)) {
      continue;
    }
    blocked.push_back(held(r) ? Interval{std::numeric_limits<TimeNs>::min(), r.window.end}
                              : r.window);
  }
  std::vector<TimeNs> points{from, until};
  for (const Interval& b : blocked) {
    for (TimeNs t : {b.start, b.end}) {
      if (t > from && t < until) points.push_back(t);
    }
  }
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  std::vector<Interval> free;
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    const TimeNs a = points[i];
    const bool is_blocked =
        std::any_of(blocked.begin(), blocked.end(), [&](const Interval& b) { return b.contains(a); });
    if (is_blocked) continue;
    if (!free.empty() && free.back().end == a) {
      free.back().end = points[i + 1];
    } else {
      free.push_back(Interval{a, points[i + 1]});
    }
  }
  return free;
}

Status ReferenceTimelines::admit(const std::vector<Reservation>& items,
                                 const std::vector<ExpectedVersion>& expected) const {
  const std::size_t n = conflicts_.size();
  if (items.empty()) return fail(ErrorCode::invalid_argument, "no items");
  for (std::size_t i = 0; i < items.size(); ++i) {
    const Reservation& r = items[i];
    if (r.agent.empty() || r.agent != items[0].agent || r.route != items[0].route ||
        !r.window.valid() || r.origin >= n ||
        (r.entity < n && r.entity != r.origin && !in_conflict_set(r.origin, r.entity))) {
      return fail(ErrorCode::invalid_argument, "bad item");
    }
    for (std::size_t j = 0; j < i; ++j) {
      const Reservation& q = items[j];
      if (q.step == r.step && (q.origin != r.origin || q.window != r.window || q.entity == r.entity)) {
        return fail(ErrorCode::invalid_argument, "inconsistent step");
      }
    }
  }
  for (const Reservation& r : items) {
    if (r.entity >= n) return fail(ErrorCode::not_found, "entity");
  }
  for (const ExpectedVersion& ev : expected) {
    if (ev.entity >= n) return fail(ErrorCode::not_found, "expected entity");
  }
  for (const ExpectedVersion& ev : expected) {
    if (versions_[ev.entity] != ev.version) return fail(ErrorCode::conflict, "version");
  }
  for (const Reservation& r : items) {
    for (const Item& item : items_) {
      const Reservation& q = item.reservation;
      if (q.entity != r.entity) continue;
      if (q.agent == r.agent && q.route == r.route && q.step == r.step) {
        return fail(ErrorCode::conflict, "step twice");
      }
      if (q.agent != r.agent && origins_conflict(conflicts_, q.origin, r.origin) &&
          (q.window.overlaps(r.window) || (held(q) && r.window.start < q.window.start))) {
        return fail(ErrorCode::conflict, "overlap or overtaking a holder");
      }
    }
    for (const Lock& lock : locks_) {
      if (lock.entity == r.entity && lock.window.overlaps(r.window)) {
        return fail(ErrorCode::conflict, "lock");
      }
    }
  }
  return {};
}

void ReferenceTimelines::add_committed(const std::vector<Reservation>& items) {
  for (const Reservation& r : items) items_.push_back(Item{r, 0});
  const std::vector<Grant> grants = grant_everywhere();
  pending_grants_.insert(pending_grants_.end(), grants.begin(), grants.end());
}

Result<PrepareId> ReferenceTimelines::prepare(const std::vector<Reservation>& items,
                                              const std::vector<ExpectedVersion>& expected,
                                              TimeNs expires_at) {
  if (Status admitted = admit(items, expected); !admitted) return unexpected(admitted.error());
  return versioned([&]() -> Result<PrepareId> {
    const PrepareId id = next_prepare_++;
    for (Reservation r : items) {
      r.prepared = true;
      items_.push_back(Item{r, id});
    }
    prepared_[id] = PreparedSet{items[0].agent, items[0].route, expires_at};
    return id;
  });
}

Status ReferenceTimelines::commit(PrepareId id) {
  if (!prepared_.contains(id)) return fail(ErrorCode::not_found, "unknown");
  return versioned([&]() -> Status {
    std::vector<Reservation> committed;
    for (const Item& item : items_) {
      if (item.prepare == id) {
        committed.push_back(item.reservation);
        committed.back().prepared = false;
      }
    }
    std::erase_if(items_, [&](const Item& item) { return item.prepare == id; });
    prepared_.erase(id);
    add_committed(committed);
    return {};
  });
}

void ReferenceTimelines::drop_prepared(PrepareId id) {
  std::erase_if(items_, [&](const Item& item) { return item.prepare == id; });
  prepared_.erase(id);
  const std::vector<Grant> grants = grant_everywhere();
  pending_grants_.insert(pending_grants_.end(), grants.begin(), grants.end());
}

Status ReferenceTimelines::abort(PrepareId id) {
  if (!prepared_.contains(id)) return fail(ErrorCode::not_found, "unknown");
  return versioned([&]() -> Status {
    drop_prepared(id);
    return {};
  });
}

std::vector<PrepareId> ReferenceTimelines::expire(TimeNs now) {
  return versioned([&] {
    std::vector<PrepareId> expired;
    for (const auto& [id, set] : prepared_) {
      if (set.expires_at <= now) expired.push_back(id);
    }
    for (PrepareId id : expired) drop_prepared(id);
    return expired;
  });
}

std::vector<Grant> ReferenceTimelines::take_grants() {
  return std::exchange(pending_grants_, {});
}

Status ReferenceTimelines::reserve(const AgentId& agent, RouteId route,
                                   const std::vector<RouteStep>& steps) {
  if (steps.empty() || agent.empty()) return fail(ErrorCode::invalid_argument, "bad route");
  for (const RouteStep& s : steps) {
    if (!s.window.valid()) return fail(ErrorCode::invalid_argument, "bad window");
  }
  for (const RouteStep& s : steps) {
    if (s.entity >= conflicts_.size()) return fail(ErrorCode::not_found, "entity");
  }
  std::vector<Reservation> items;
  for (std::uint32_t i = 0; i < steps.size(); ++i) {
    items.push_back(Reservation{agent, route, i, steps[i].entity, steps[i].entity, steps[i].window});
    for (EntityIndex f : conflicts_[steps[i].entity]) {
      items.push_back(Reservation{agent, route, i, f, steps[i].entity, steps[i].window});
    }
  }
  if (Status admitted = admit(items, {}); !admitted) return admitted;
  return versioned([&]() -> Status {
    add_committed(items);
    return {};
  });
}

Result<Allocation> ReferenceTimelines::allocate(const AgentId& agent, EntityIndex entity) {
  if (agent.empty()) return fail(ErrorCode::invalid_argument, "agent");
  if (entity >= conflicts_.size()) return fail(ErrorCode::not_found, "entity");
  auto holder = holders_.find(entity);
  if (holder != holders_.end() && holder->second.agent == agent) return Allocation{true, 0};
  const Reservation* mine = first_committed_real(agent, entity);
  if (mine == nullptr) return fail(ErrorCode::not_found, "no reservation");
  const std::size_t ahead = others_before(agent, entity, mine->window.start);
  return versioned([&]() -> Result<Allocation> {
    if (holder == holders_.end() && ahead == 0) {
      holders_[entity] = HeldStep{agent, mine->route, mine->step};
      std::erase(waiting_[entity], agent);
      return Allocation{true, 0};
    }
    auto& waiting = waiting_[entity];
    if (std::find(waiting.begin(), waiting.end(), agent) == waiting.end()) waiting.push_back(agent);
    return Allocation{false, ahead};
  });
}

Result<std::vector<Grant>> ReferenceTimelines::release(const AgentId& agent, EntityIndex entity) {
  if (agent.empty()) return fail(ErrorCode::invalid_argument, "agent");
  if (entity >= conflicts_.size()) return fail(ErrorCode::not_found, "entity");
  auto holder = holders_.find(entity);
  if (holder == holders_.end() || holder->second.agent != agent) {
    return fail(ErrorCode::not_permitted, "not the holder");
  }
  return versioned([&]() -> Result<std::vector<Grant>> {
    const HeldStep held_step = holder->second;
    std::erase_if(items_, [&](const Item& item) {
      const Reservation& r = item.reservation;
      return r.agent == agent && r.route == held_step.route && r.step == held_step.step &&
             r.origin == entity;
    });
    holders_.erase(holder);
    return grant_everywhere();
  });
}

Result<std::vector<Grant>> ReferenceTimelines::cancel_route(const AgentId& agent, RouteId route) {
  if (agent.empty()) return fail(ErrorCode::invalid_argument, "agent");
  const auto of_route = [&](const Item& item) {
    return item.reservation.agent == agent && item.reservation.route == route;
  };
  if (std::none_of(items_.begin(), items_.end(), of_route)) {
    return fail(ErrorCode::not_found, "route");
  }
  return versioned([&]() -> Result<std::vector<Grant>> {
    std::vector<Item> kept;
    for (const Item& item : items_) {
      if (!of_route(item) || held(item.reservation)) kept.push_back(item);
    }
    items_ = std::move(kept);
    std::erase_if(prepared_, [&](const auto& entry) {
      return entry.second.agent == agent && entry.second.route == route;
    });
    return grant_everywhere();
  });
}

Result<DelayReport> ReferenceTimelines::delay(const AgentId& agent, RouteId route,
                                              EntityIndex entity, DurationNs by) {
  if (agent.empty() || by <= 0) return fail(ErrorCode::invalid_argument, "bad delay");
  if (entity >= conflicts_.size()) return fail(ErrorCode::not_found, "entity");
  std::optional<std::uint32_t> real_step, shadow_step;
  for (const Item& item : items_) {
    const Reservation& r = item.reservation;
    if (r.entity != entity || r.agent != agent || r.route != route) continue;
    auto& slot = r.origin == entity ? real_step : shadow_step;
    slot = slot ? std::min(*slot, r.step) : r.step;
  }
  if (!real_step && !shadow_step) return fail(ErrorCode::not_found, "no reservation");
  const std::uint32_t step = real_step ? *real_step : *shadow_step;

  // Per route: the raises (from step, level); level(k) = largest raise with from <= k.
  std::map<RouteKey, std::vector<std::pair<std::uint64_t, DurationNs>>> raises;
  const auto level = [&](const Reservation& r, std::uint64_t k) {
    DurationNs best = 0;
    for (const auto& [from, value] : raises[{r.agent, r.route}]) {
      if (from <= k) best = std::max(best, value);
    }
    return best;
  };
  const auto new_end = [&](const Reservation& r) {
    return r.window.end == kForever ? kForever : r.window.end + level(r, r.step + 1ULL);
  };
  raises[{agent, route}].push_back({step + 1ULL, by});
  for (bool changed = true; changed;) {
    changed = false;
    for (const Item& x : items_) {
      for (const Item& y : items_) {
        const Reservation& a = x.reservation;
        const Reservation& b = y.reservation;
        if (a.entity != b.entity || a.agent == b.agent || a.window.start >= b.window.start ||
            !origins_conflict(conflicts_, a.origin, b.origin)) {
          continue;
        }
        const TimeNs blocker_end = new_end(a);
        if (b.window.start + level(b, b.step) < blocker_end) {
          raises[{b.agent, b.route}].push_back({b.step, blocker_end - b.window.start});
          changed = true;
        }
      }
    }
  }
  std::vector<Item> moved_items = items_;
  std::set<ReservationKey> moved;
  for (Item& item : moved_items) {
    Reservation& r = item.reservation;
    Interval w;
    if (add_overflows(r.window.start, level(r, r.step), w.start)) {
      return fail(ErrorCode::invalid_argument, "overflow");
    }
    w.end = r.window.end;
    if (w.end != kForever && add_overflows(r.window.end, level(r, r.step + 1ULL), w.end)) {
      return fail(ErrorCode::invalid_argument, "overflow");
    }
    if (w != r.window) moved.insert(key_of(r));
    r.window = w;
  }
  return versioned([&]() -> Result<DelayReport> {
    items_ = std::move(moved_items);
    DelayReport report;
    const auto shift_of = [&](const RouteKey& key) {
      std::uint64_t first = std::numeric_limits<std::uint64_t>::max();
      DurationNs largest = 0;
      for (const auto& [from, value] : raises[key]) {
        first = std::min(first, from);
        largest = std::max(largest, value);
      }
      return Shift{key.first, key.second, static_cast<std::uint32_t>(first == 0 ? 0 : first - 1),
                   largest};
    };
    report.shifts.push_back(shift_of({agent, route}));
    for (const auto& [key, list] : raises) {
      if (key != RouteKey{agent, route} && !list.empty()) report.shifts.push_back(shift_of(key));
    }
    for (const Item& item : items_) {
      const Reservation& r = item.reservation;
      if (!moved.contains(key_of(r))) continue;
      for (const Lock& lock : locks_) {
        if (lock.entity == r.entity && lock.window.overlaps(r.window)) {
          report.hit_locks.push_back(r);
          break;
        }
      }
    }
    std::sort(report.hit_locks.begin(), report.hit_locks.end(),
              [](const Reservation& a, const Reservation& b) {
                return a.entity != b.entity ? a.entity < b.entity : timeline_order(a, b);
              });
    return report;
  });
}

Result<LockReport> ReferenceTimelines::lock(EntityIndex entity, Interval window,
                                            const std::string& operator_id,
                                            const std::string& reason) {
  if (!window.valid() || operator_id.empty()) return fail(ErrorCode::invalid_argument, "bad");
  if (entity >= conflicts_.size()) return fail(ErrorCode::not_found, "entity");
  return versioned([&]() -> Result<LockReport> {
    LockReport report;
    report.id = next_lock_++;
    for (const Reservation& r : timeline(entity).reservations) {
      if (r.window.overlaps(window)) report.hit.push_back(r);
    }
    locks_.push_back(Lock{report.id, entity, window, operator_id, reason});
    return report;
  });
}

Status ReferenceTimelines::unlock(LockId id) {
  if (std::none_of(locks_.begin(), locks_.end(), [&](const Lock& l) { return l.id == id; })) {
    return fail(ErrorCode::not_found, "unknown");
  }
  return versioned([&]() -> Status {
    std::erase_if(locks_, [&](const Lock& l) { return l.id == id; });
    return {};
  });
}

// ---- invariant checkers ---------------------------------------------------------------

std::vector<std::string> check_exclusive(const Snapshot& s) {
  std::vector<std::string> out;
  const std::size_t n = s.timelines.size();
  for (EntityIndex e = 0; e < n; ++e) {
    const auto& rs = s.timelines[e].reservations;
    for (std::size_t i = 0; i < rs.size(); ++i) {
      for (std::size_t j = i + 1; j < rs.size(); ++j) {
        if (rs[i].agent != rs[j].agent && rs[i].window.overlaps(rs[j].window) &&
            origins_conflict(s.conflicts, rs[i].origin, rs[j].origin)) {
          out.push_back("I1 timeline " + std::to_string(e) + ": " + text(rs[i]) + " overlaps " +
                        text(rs[j]));
        }
      }
    }
  }
  // Real reservations pairwise over e and C(e).
  for (EntityIndex e = 0; e < n; ++e) {
    std::vector<EntityIndex> place = s.conflicts[e];
    place.push_back(e);
    for (const Reservation& r : s.timelines[e].reservations) {
      if (r.shadow()) continue;
      for (EntityIndex f : place) {
        for (const Reservation& q : s.timelines[f].reservations) {
          if (!q.shadow() && q.agent != r.agent && q.window.overlaps(r.window)) {
            out.push_back("I1 conflict set of " + std::to_string(e) + ": " + text(r) +
                          " overlaps " + text(q));
          }
        }
      }
    }
  }
  // Shadows and their real reservations come and go together.
  const auto same_step = [](const Reservation& a, const Reservation& b) {
    return a.agent == b.agent && a.route == b.route && a.step == b.step &&
           a.origin == b.origin && a.window == b.window && a.prepared == b.prepared;
  };
  for (EntityIndex e = 0; e < n; ++e) {
    for (const Reservation& r : s.timelines[e].reservations) {
      if (!r.shadow()) {
        for (EntityIndex f : s.conflicts[e]) {
          const auto& on_f = s.timelines[f].reservations;
          if (std::none_of(on_f.begin(), on_f.end(),
                           [&](const Reservation& q) { return same_step(q, r); })) {
            out.push_back("shadow missing on " + std::to_string(f) + " for " + text(r));
          }
        }
      } else {
        const auto& on_origin = s.timelines[r.origin].reservations;
        if (!contains(s.conflicts[r.origin], e) ||
            std::none_of(on_origin.begin(), on_origin.end(),
                         [&](const Reservation& q) { return same_step(q, r) && !q.shadow(); })) {
          out.push_back("shadow without its real reservation: " + text(r));
        }
      }
    }
  }
  return out;
}

std::vector<std::string> check_allocations(const Snapshot& s) {
  std::vector<std::string> out;
  const std::size_t n = s.timelines.size();
  const auto first_committed_real = [&](const AgentId& agent, EntityIndex e) {
    const Reservation* first = nullptr;
    for (const Reservation& r : s.timelines[e].reservations) {
      if (r.agent == agent && !r.shadow() && !r.prepared &&
          (first == nullptr || r.window.start < first->window.start)) {
        first = &r;
      }
    }
    return first;
  };
  const auto others_before = [&](const AgentId& agent, EntityIndex e, TimeNs start) {
    std::size_t count = 0;
    for (const Reservation& r : s.timelines[e].reservations) {
      if (r.agent != agent && r.window.start < start) ++count;
    }
    return count;
  };
  for (EntityIndex e = 0; e < n; ++e) {
    const Timeline& t = s.timelines[e];
    const std::string where = "entity " + std::to_string(e) + ": ";
    auto held = s.held.find(e);
    if (t.holder.has_value() != (held != s.held.end()) ||
        (t.holder && *t.holder != held->second.agent)) {
      out.push_back(where + "holder and held reservation disagree");
      continue;
    }
    if (t.holder) {
      const HeldStep& h = held->second;
      const Reservation* mine = nullptr;
      for (const Reservation& r : t.reservations) {
        if (r.agent == h.agent && r.route == h.route && r.step == h.step && !r.shadow()) mine = &r;
      }
      if (mine == nullptr || mine->prepared) {
        out.push_back(where + "holder " + h.agent + " has no committed held reservation");
      } else if (others_before(h.agent, e, mine->window.start) > 0) {
        out.push_back(where + "I2: another agent's reservation precedes holder " + h.agent);
      }
      for (EntityIndex f : s.conflicts[e]) {
        if (s.timelines[f].holder && *s.timelines[f].holder != h.agent) {
          out.push_back(where + "I1: " + h.agent + " and " + *s.timelines[f].holder +
                        " hold conflicting entities " + std::to_string(e) + ", " +
                        std::to_string(f));
        }
      }
    }
    std::set<AgentId> seen;
    for (const AgentId& w : t.waiting) {
      if (!seen.insert(w).second) out.push_back(where + w + " waits twice");
      if (t.holder == w) out.push_back(where + "holder " + w + " also waits");
      const Reservation* mine = first_committed_real(w, e);
      if (mine == nullptr) {
        out.push_back(where + w + " waits without a committed reservation");
      } else if (!t.holder && others_before(w, e, mine->window.start) == 0) {
        out.push_back(where + w + " waits although it could be granted");
      }
    }
  }
  return out;
}

std::vector<std::string> check_delay(const Snapshot& before, const Snapshot& after,
                                     const AgentId& agent, RouteId route, std::uint32_t step,
                                     DurationNs by, const DelayReport& report) {
  std::vector<std::string> out;
  std::map<ReservationKey, Reservation> old_by_key, new_by_key;
  for (const Timeline& t : before.timelines) {
    for (const Reservation& r : t.reservations) old_by_key[key_of(r)] = r;
  }
  for (const Timeline& t : after.timelines) {
    for (const Reservation& r : t.reservations) new_by_key[key_of(r)] = r;
  }
  if (old_by_key.size() != new_by_key.size()) out.push_back("delay added or removed reservations");
  std::set<RouteKey> moved_routes;
  std::set<ReservationKey> moved;
  std::map<RouteKey, DurationNs> largest_move;
  std::map<RouteKey, std::uint32_t> first_moved_step;
  for (const auto& [key, old] : old_by_key) {
    auto found = new_by_key.find(key);
    if (found == new_by_key.end()) {
      out.push_back("delay lost " + text(old));
      continue;
    }
    const Reservation& now = found->second;
    Reservation same_but_window = now;
    same_but_window.window = old.window;
    if (!(same_but_window == old)) out.push_back("delay changed more than the window of " + text(old));
    const RouteKey route_key{old.agent, old.route};
    if (old.agent == agent && old.route == route) {
      Interval expected = old.window;
      if (old.step >= step && expected.end != kForever) expected.end += by;
      if (old.step > step) expected.start += by;
      if (now.window != expected) {
        out.push_back("delayed route: " + text(old) + " became " + text(now) + ", expected a shift by " +
                      std::to_string(by));
      }
    }
    if (now.window != old.window) {
      moved.insert(key);
      moved_routes.insert(route_key);
      DurationNs move = now.window.start - old.window.start;
      if (old.window.end != kForever) move = std::max(move, now.window.end - old.window.end);
      largest_move[route_key] = std::max(largest_move[route_key], move);
      auto [first, inserted] = first_moved_step.emplace(route_key, old.step);
      if (!inserted) first->second = std::min(first->second, old.step);
      if (now.window.start < old.window.start || now.window.end < old.window.end) {
        out.push_back("delay moved " + text(old) + " earlier");
      }
    }
  }
  // Order of different agents on every timeline.
  for (std::size_t e = 0; e < before.timelines.size(); ++e) {
    const auto& rs = before.timelines[e].reservations;
    for (const Reservation& a : rs) {
      for (const Reservation& b : rs) {
        if (a.agent == b.agent || a.window.start >= b.window.start ||
            !origins_conflict(before.conflicts, a.origin, b.origin)) {
          continue;
        }
        const Reservation& na = new_by_key[key_of(a)];
        const Reservation& nb = new_by_key[key_of(b)];
        if (na.window.start >= nb.window.start) {
          out.push_back("I3 order changed on " + std::to_string(e) + ": " + text(a) + " before " +
                        text(b) + ", now " + text(na) + " / " + text(nb));
        }
      }
    }
    const Timeline& t0 = before.timelines[e];
    const Timeline& t1 = after.timelines[e];
    if (t0.locks != t1.locks || t0.holder != t1.holder || t0.waiting != t1.waiting) {
      out.push_back("delay changed locks or allocations of " + std::to_string(e));
    }
  }
  if (before.held != after.held) out.push_back("delay changed held reservations");
  // The report.
  if (report.shifts.empty() || report.shifts.front() != Shift{agent, route, step, by}) {
    out.push_back("the report does not name the delayed route first with its step and delay");
  }
  std::set<RouteKey> reported;
  for (std::size_t i = 0; i < report.shifts.size(); ++i) {
    const Shift& shift = report.shifts[i];
    const RouteKey key{shift.agent, shift.route};
    if (!reported.insert(key).second) out.push_back("route reported twice: " + shift.agent);
    if (i == 0) continue;
    if (!moved_routes.contains(key)) {
      out.push_back("reported but not moved: " + shift.agent + "/" + std::to_string(shift.route));
    } else if (shift.by != largest_move[key] || shift.from_step > first_moved_step[key]) {
      out.push_back("wrong shift reported for " + shift.agent + "/" + std::to_string(shift.route));
    }
  }
  // A pushed route moves no further than needed: where its largest shift begins, one of its
  // reservations starts exactly when a reservation of another agent before it now ends.
  for (std::size_t i = 1; i < report.shifts.size(); ++i) {
    const RouteKey key{report.shifts[i].agent, report.shifts[i].route};
    std::optional<std::uint32_t> first_step;
    for (const auto& [k, old] : old_by_key) {
      if (RouteKey{old.agent, old.route} == key &&
          new_by_key[k].window.start - old.window.start == largest_move[key] &&
          (!first_step || old.step < *first_step)) {
        first_step = old.step;
      }
    }
    bool tight = false;
    for (const auto& [k, old] : old_by_key) {
      if (RouteKey{old.agent, old.route} != key || !first_step || old.step != *first_step) continue;
      const Reservation& now = new_by_key[k];
      for (const Reservation& x : before.timelines[old.entity].reservations) {
        if (x.agent != old.agent && x.window.start < old.window.start &&
            origins_conflict(before.conflicts, x.origin, old.origin) &&
            new_by_key[key_of(x)].window.end == now.window.start) {
          tight = true;
        }
      }
    }
    if (!tight) out.push_back("pushed further than needed: " + key.first + "/" + std::to_string(key.second));
  }
  for (const RouteKey& key : moved_routes) {
    if (!reported.contains(key)) {
      out.push_back("moved but not reported: " + key.first + "/" + std::to_string(key.second));
    }
  }
  // hit_locks: exactly the moved reservations that overlap a lock now.
  std::set<ReservationKey> expected_hits, reported_hits;
  for (const ReservationKey& key : moved) {
    const Reservation& now = new_by_key[key];
    for (const Lock& lock : after.timelines[now.entity].locks) {
      if (lock.window.overlaps(now.window)) expected_hits.insert(key);
    }
  }
  for (const Reservation& r : report.hit_locks) {
    reported_hits.insert(key_of(r));
    if (new_by_key[key_of(r)] != r) out.push_back("hit_locks reports a stale window: " + text(r));
  }
  if (expected_hits != reported_hits) out.push_back("hit_locks is not the set of moved reservations in locks");
  return out;
}

std::vector<std::string> check_locks(const Snapshot& s,
                                     const std::set<std::pair<ReservationKey, LockId>>& excused) {
  std::vector<std::string> out;
  for (const Timeline& t : s.timelines) {
    for (const Lock& lock : t.locks) {
      for (const Reservation& r : t.reservations) {
        if (r.window.overlaps(lock.window) && !excused.contains({key_of(r), lock.id})) {
          out.push_back("I4: " + text(r) + " overlaps lock " + std::to_string(lock.id) +
                        " but was neither hit by it nor moved into it by a delay");
        }
      }
    }
  }
  return out;
}

}  // namespace drover::topology::reference
