// TimelineSet: allocation strictly in reservation order (I2), release, cancel_route, and
// the grants of waiting requests that a removal makes possible.

#include <algorithm>
#include <string>
#include <utility>

#include "drover/topology/timeline.hpp"
#include "timeline_impl.hpp"

namespace drover::topology {

const Reservation* TimelineSet::Impl::first_committed_real(const Timeline& timeline,
                                                          const AgentId& agent) {
  for (const Reservation& r : timeline.reservations) {  // in start order
    if (r.agent == agent && !r.shadow() && !r.prepared) return &r;
  }
  return nullptr;
}

std::size_t TimelineSet::Impl::others_before(const Timeline& timeline, const AgentId& agent,
                                             TimeNs start) {
  return static_cast<std::size_t>(
      std::count_if(timeline.reservations.begin(), timeline.reservations.end(),
                    [&](const Reservation& r) { return r.agent != agent && r.window.start < start; }));
}

std::vector<Grant> TimelineSet::Impl::grant_waiting(TimelineSet& set, const TouchedSet& entities,
                                                    TouchedSet& touched) {
  std::vector<Grant> grants;
  for (EntityIndex entity : entities) {
    Timeline& t = set.timelines_[entity];
    if (std::erase_if(t.waiting, [&](const AgentId& agent) {
          return first_committed_real(t, agent) == nullptr;
        }) > 0) {
      touched.insert(entity);
    }
    if (t.holder) continue;
    for (auto waiting = t.waiting.begin(); waiting != t.waiting.end(); ++waiting) {
      const Reservation* mine = first_committed_real(t, *waiting);
      if (others_before(t, *waiting, mine->window.start) > 0) continue;
      if (set.grant_filter_.may_grant && !set.grant_filter_.may_grant(*waiting, entity)) continue;
      set.held_[entity] = AllocatedStep{mine->route, mine->step};
      t.holder = *waiting;
      revise_around(set, entity);
      grants.push_back(Grant{*waiting, entity});
      t.waiting.erase(waiting);
      touched.insert(entity);
      break;  // one holder per entity
    }
  }
  return grants;
}

Result<Allocation> TimelineSet::allocate(const AgentId& agent, EntityIndex entity) {
  if (agent.empty()) return fail(ErrorCode::invalid_argument, "allocate: empty agent id");
  if (!owns(entity)) {
    return fail(ErrorCode::not_found,
                "allocate: entity " + std::to_string(entity) + " is not owned by this set");
  }
  Timeline& t = timelines_[entity];
  if (t.holder == agent) return Allocation{true, 0};
  const Reservation* mine = Impl::first_committed_real(t, agent);
  if (mine == nullptr) {
    return fail(ErrorCode::not_found, "allocate: agent " + agent +
                                          " has no committed reservation on entity " +
                                          std::to_string(entity));
  }
  const std::size_t ahead = Impl::others_before(t, agent, mine->window.start);
  if (!t.holder && ahead == 0) {
    held_[entity] = AllocatedStep{mine->route, mine->step};
    t.holder = agent;
    std::erase(t.waiting, agent);
    ++t.version;
    Impl::revise_around(*this, entity);
    return Allocation{true, 0};
  }
  // A holder's allocated reservation always comes first (nobody may be placed before
  // it), so a request behind a holder has ahead >= 1.
  if (std::find(t.waiting.begin(), t.waiting.end(), agent) == t.waiting.end()) {
    t.waiting.push_back(agent);
    ++t.version;
    Impl::revise_around(*this, entity);
  }
  return Allocation{false, ahead};
}

std::optional<AllocatedStep> TimelineSet::allocated_step(EntityIndex entity) const {
  return owns(entity) ? held_[entity] : std::nullopt;
}

AgentHoldings TimelineSet::holdings_of(const AgentId& agent) const {
  AgentHoldings out;
  for (EntityIndex entity = 0; entity < timelines_.size(); ++entity) {
    if (!owns(entity)) continue;
    const Timeline& t = timelines_[entity];
    if (t.holder == agent && held_[entity]) out.held.emplace_back(entity, *held_[entity]);
    for (const Reservation& r : t.reservations) {
      if (r.agent == agent) out.routes.push_back(r.route);
    }
  }
  std::sort(out.routes.begin(), out.routes.end());
  out.routes.erase(std::unique(out.routes.begin(), out.routes.end()), out.routes.end());
  return out;
}

Result<std::vector<Grant>> TimelineSet::release(const AgentId& agent, EntityIndex entity) {
  if (agent.empty()) return fail(ErrorCode::invalid_argument, "release: empty agent id");
  if (!owns(entity)) {
    return fail(ErrorCode::not_found,
                "release: entity " + std::to_string(entity) + " is not owned by this set");
  }
  Timeline& t = timelines_[entity];
  if (t.holder != agent) {
    return fail(ErrorCode::not_permitted,
                "release: agent " + agent + " does not hold entity " + std::to_string(entity) +
                    (t.holder ? " (held by " + *t.holder + ")" : " (nobody holds it)"));
  }
  const AllocatedStep held = *held_[entity];
  TouchedSet touched{entity};
  const auto allocated = [&](const Reservation& r) {
    return r.agent == agent && r.route == held.route && r.step == held.step &&
           r.origin == entity;
  };
  std::erase_if(t.reservations, allocated);
  for (EntityIndex f : conflict_sets_[entity]) {
    if (owns(f) && std::erase_if(timelines_[f].reservations, allocated) > 0) touched.insert(f);
  }
  t.holder.reset();
  held_[entity].reset();
  Impl::revise_around(*this, entity);
  std::vector<Grant> grants = Impl::grant_waiting(*this, TouchedSet(touched), touched);
  Impl::bump_versions(*this, touched);
  return grants;
}

Result<std::vector<Grant>> TimelineSet::release_shadows(const AgentId& agent, RouteId route, std::uint32_t step,
                                                        EntityIndex origin) {
  if (agent.empty()) return fail(ErrorCode::invalid_argument, "release_shadows: empty agent id");
  if (origin >= conflict_sets_.size()) {
    return fail(ErrorCode::not_found, "release_shadows: no entity " + std::to_string(origin));
  }
  if (owns(origin)) {
    return fail(ErrorCode::not_permitted, "release_shadows: entity " + std::to_string(origin) +
                                              " is owned here: its allocation is given up with release");
  }
  const auto of_step = [&](const Reservation& r) {
    return r.agent == agent && r.route == route && r.step == step && r.origin == origin;
  };
  TouchedSet touched;
  for (EntityIndex f : conflict_sets_[origin]) {
    if (owns(f) && std::erase_if(timelines_[f].reservations, of_step) > 0) touched.insert(f);
  }
  std::vector<Grant> grants = Impl::grant_waiting(*this, TouchedSet(touched), touched);
  Impl::bump_versions(*this, touched);
  return grants;
}

Result<std::vector<Grant>> TimelineSet::cancel_route(const AgentId& agent, RouteId route,
                                                     const std::vector<std::uint32_t>& held_steps) {
  if (agent.empty()) return fail(ErrorCode::invalid_argument, "cancel_route: empty agent id");
  const auto of_route = [&](const Reservation& r) { return r.agent == agent && r.route == route; };
  const bool known = std::any_of(timelines_.begin(), timelines_.end(), [&](const Timeline& t) {
    return std::any_of(t.reservations.begin(), t.reservations.end(), of_route);
  });
  if (!known) {
    return fail(ErrorCode::not_found, "cancel_route: agent " + agent + " has no route " +
                                          std::to_string(route) + " here");
  }
  TouchedSet touched;
  // Decide with the allocation state before anything is removed.
  const auto held_abroad = [&](const Reservation& r) {
    return !owns(r.origin) && std::find(held_steps.begin(), held_steps.end(), r.step) != held_steps.end();
  };
  Impl::remove_reservations(
      *this,
      [&](const Reservation& r) { return of_route(r) && !Impl::is_held(*this, r) && !held_abroad(r); },
      touched);
  std::erase_if(prepared_, [&](const auto& entry) {
    return entry.second.agent == agent && entry.second.route == route;
  });
  std::vector<Grant> grants = Impl::grant_waiting(*this, TouchedSet(touched), touched);
  Impl::bump_versions(*this, touched);
  return grants;
}

}  // namespace drover::topology
