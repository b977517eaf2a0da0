#include "drover/carp/planner.hpp"

#include <algorithm>
#include <deque>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "heuristic.hpp"
#include "traversal.hpp"
#include "window_search.hpp"

namespace drover::carp {

using topology::EntityIndex;
using topology::Interval;
using topology::TimelineSet;

namespace {

constexpr std::size_t kVehicleClasses = 8;

std::string time_text(TimeNs t) {
  return t == kForever ? std::string("forever") : fmt::format("{:.3f} s", ns_to_seconds(t));
}

PlanError error(PlanFailure reason, std::string message) {
  return PlanError{reason, std::move(message), {}};
}

std::string lock_text(const topology::Topology& topology, EntityIndex place,
                      const topology::Lock& lock) {
  return fmt::format("lock {} on '{}' [{}, {}) by {}: {}", lock.id, topology.id(place),
                     time_text(lock.window.start), time_text(lock.window.end), lock.operator_id,
                     lock.reason);
}

/// A reservation as it blocks `place` (its own entity, or one it shadows).
std::string reservation_text(const topology::Topology& topology, EntityIndex place,
                             const topology::Reservation& r) {
  return fmt::format("agent {} route {} holds '{}'{} [{}, {})", r.agent, r.route,
                     topology.id(r.origin),
                     r.shadow() ? fmt::format(" (conflicting with '{}')", topology.id(place))
                                : std::string(),
                     time_text(r.window.start), time_text(r.window.end));
}

/// The first lock (where `with_locks`), then the first reservation of another agent than
/// `agent`, that `blocks` on `entity` or a member of its conflict set, described; nullopt if
/// there is none.
template <class Blocks>
std::optional<std::string> first_blocker_text(const topology::Topology& topology,
                                              const TimelineSet& timelines, EntityIndex entity,
                                              std::string_view agent, Blocks blocks,
                                              bool with_locks = true) {
  std::vector<EntityIndex> places{entity};
  places.insert(places.end(), topology.conflicts(entity).begin(),
                topology.conflicts(entity).end());
  for (const EntityIndex place : places) {
    if (!timelines.owns(place)) continue;
    const topology::Timeline& timeline = timelines.timeline(place);
    for (const topology::Lock& lock : timeline.locks) {
      if (with_locks && blocks(lock.window)) return lock_text(topology, place, lock);
    }
    for (const topology::Reservation& r : timeline.reservations) {
      if (r.agent != agent && blocks(r.window)) return reservation_text(topology, place, r);
    }
  }
  return std::nullopt;
}

/// What keeps `agent` off `entity` at time t: a lock or another agent's reservation on the
/// entity or its conflict set (the blockers of TimelineSet::free_windows).
std::string blocker_text(const topology::Topology& topology, const TimelineSet& timelines,
                         EntityIndex entity, std::string_view agent, TimeNs t) {
  return first_blocker_text(topology, timelines, entity, agent,
                            [t](const Interval& window) { return window.contains(t); })
      .value_or("another agent's allocation there (nobody may come before a holder)");
}

/// What holds `entity` (or a member of its conflict set) open-ended against `agent`: the
/// reason it is never free for good, named as the open-ended lock or reservation itself
/// (not whatever else overlaps its start); a reservation only, unless `locked` (the locks
/// are to blame). Falls back to what blocks at `from`.
std::string forever_blocker_text(const topology::Topology& topology, const TimelineSet& timelines,
                                 EntityIndex entity, std::string_view agent, TimeNs from,
                                 bool locked) {
  const auto open_ended = first_blocker_text(
      topology, timelines, entity, agent, [](const Interval& window) { return window.end == kForever; },
      locked);
  return open_ended ? *open_ended : blocker_text(topology, timelines, entity, agent, from);
}

/// Adds to `holders` the agents other than `agent` that hold `entity` open-ended, on the
/// entity itself or on a member of its conflict set (whose shadows the entity's own
/// timeline carries).
void add_open_ended_holders(const TimelineSet& timelines, EntityIndex entity, std::string_view agent,
                            std::vector<std::string>& holders) {
  if (!timelines.owns(entity)) return;
  // Nobody holds it open-ended when a newcomer can have it for good: most entities.
  const std::span<const Interval> free = timelines.newcomer_windows(entity).windows();
  if (!free.empty() && free.back().end == kForever) return;
  // Every reservation on the timeline blocks a newcomer, so one held open-ended blocks it
  // from its start on: it starts no earlier than the newcomer's last window ends. Only the
  // timeline's tail from there is read (sorted by start, and cold), so an explanation costs
  // log n reads of a long timeline, not n. Bench plan, random N = 400: reading whole
  // timelines here was a tenth of the planner's last-level misses in callgrind's cache
  // model; in time, within the noise (in-process A/B: 0.97 to 1.03).
  const std::vector<topology::Reservation>& reservations =
      timelines.timeline(entity).reservations;
  const auto tail =
      free.empty() ? reservations.begin()
                   : std::partition_point(reservations.begin(), reservations.end(),
                                          [from = free.back().end](const topology::Reservation& r) {
                                            return r.window.start < from;
                                          });
  for (auto r = tail; r != reservations.end(); ++r) {
    // The window first: most reservations end, and comparing it is cheaper than the agent.
    if (r->window.end == kForever && r->agent != agent) holders.push_back(r->agent);
  }
}

void sort_unique(std::vector<std::string>& names) {
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
}

/// True when some path leads from `from` to `to`, whatever the vehicle.
bool connected(const RoutingGraph& graph, EntityIndex from, EntityIndex to) {
  std::vector<std::uint8_t> seen(graph.vertex_count(), 0);
  std::deque<EntityIndex> queue{from};
  seen[from] = 1;
  while (!queue.empty()) {
    const EntityIndex v = queue.front();
    queue.pop_front();
    if (v == to) return true;
    for (ArcIndex a = graph.arcs_begin(v); a != graph.arcs_end(v); ++a) {
      const EntityIndex next = graph.arc(a).to;
      if (!seen[next]) {
        seen[next] = 1;
        queue.push_back(next);
      }
    }
  }
  return false;
}

}  // namespace

struct Planner::Impl {
  std::shared_ptr<const RoutingGraph> graph;
  PlannerOptions options;
  TraversalCache traversals{kVehicleClasses};
  HeuristicCache heuristics;
  WindowSearch search;
  std::vector<Leg> legs;
  std::vector<Interval> goal_windows;
  std::vector<Interval> start_windows;
  PlanStats stats;            ///< of the last plan's search

  Impl(std::shared_ptr<const RoutingGraph> g, PlannerOptions o)
      : graph(std::move(g)), options(o), heuristics(o.heuristic_tables) {}

  const topology::Topology& topology() const { return graph->topology(); }

  std::string vertex_name(EntityIndex v) const { return "'" + topology().id(v) + "'"; }

  /// How long after its start time a route may take: the option, cut to kLongestDuration.
  DurationNs horizon() const { return std::min(options.horizon, kLongestDuration); }

  std::optional<PlanError> check_request(const TimelineSet& timelines,
                                         const PlanRequest& request) const {
    const auto invalid = [](std::string message) {
      return error(PlanFailure::invalid_request, std::move(message));
    };
    if (options.horizon <= 0) return invalid("the planner's horizon must be > 0");
    if (options.floor_proof_after == 0) return invalid("the planner's floor_proof_after must be >= 1");
    if (options.floor_proof_budget == 0) return invalid("the planner's floor_proof_budget must be >= 1");
    if (options.quick_proof_after > 0 && options.quick_proof_budget == 0) {
      return invalid("the planner's quick_proof_budget must be >= 1 when quick_proof_after is set");
    }
    if (options.shut_in_after > 0 && (options.shut_in_region == 0 || options.shut_in_budget == 0)) {
      return invalid(fmt::format("the planner's {} must be >= 1 when shut_in_after is set",
                                 options.shut_in_region == 0 ? "shut_in_region" : "shut_in_budget"));
    }
    if (request.agent.empty()) return invalid("the agent id is empty");
    if (auto valid = validate(request.vehicle); !valid) return invalid(valid.error().message);
    if (timelines.entity_count() != topology().entity_count()) {
      return invalid(fmt::format("the timelines cover {} entities, topology '{}' has {}",
                                 timelines.entity_count(), topology().name(),
                                 topology().entity_count()));
    }
    // A set owning a part sees the rest as held by others: every failure would blame them.
    if (!timelines.owns_all()) {
      return invalid(fmt::format("the timelines own only part of topology '{}'; a planner "
                                 "needs every entity's timeline (a replica of all of them)",
                                 topology().name()));
    }
    const auto not_vertex = [&](EntityIndex v, const std::string& what) {
      return invalid(fmt::format("{}: entity {} is not a vertex of topology '{}' ({} vertices)",
                                 what, v, topology().name(), topology().vertex_count()));
    };
    if (request.start >= topology().vertex_count()) return not_vertex(request.start, "start");
    if (request.start_time < 0 || request.start_time > kLatestTime) {
      return invalid(fmt::format("start time {} ns is out of range (0 to {} ns)", request.start_time,
                                 kLatestTime));
    }
    if (request.stops.empty()) return invalid("the request has no stops");
    if (request.stops.size() > kMaxStops) {
      return invalid(fmt::format("the request has {} stops, more than the {} one request may have",
                                 request.stops.size(), kMaxStops));
    }
    DurationNs dwells = 0;  // at most kLongestDuration + one dwell: no overflow
    for (std::size_t k = 0; k < request.stops.size(); ++k) {
      // The stop's name is formatted only for an error: every plan passes here.
      const Stop& stop = request.stops[k];
      if (stop.vertex >= topology().vertex_count()) {
        return not_vertex(stop.vertex, fmt::format("stop {}", k));
      }
      if (!stop.dwell) continue;
      const bool last = k + 1 == request.stops.size();
      if (*stop.dwell < 0 || (last && *stop.dwell == 0) || *stop.dwell > kLongestDuration) {
        return invalid(fmt::format("stop {} ({}): dwell {} ns must be {} (and not huge)", k,
                                   vertex_name(stop.vertex), *stop.dwell,
                                   last ? "> 0 for the last stop, or absent for an open-ended hold"
                                        : ">= 0"));
      }
      dwells += *stop.dwell;
      if (dwells > kLongestDuration) {
        return invalid(fmt::format("the dwells of stops 0 to {} add up to more than {}, the "
                                   "longest the planner takes",
                                   k, time_text(kLongestDuration)));
      }
    }
    return std::nullopt;
  }

  std::optional<PlanError> check_usable(const Traversal& traversal,
                                        const PlanRequest& request) const {
    // The vertex's name is formatted only for an error: every plan passes here.
    const auto restricted = [&](EntityIndex v, const std::string& what) {
      return error(PlanFailure::restricted,
                   fmt::format("vehicle '{}' may not use {} {}: {}", request.vehicle.id, what,
                               vertex_name(v),
                               *restriction_violation(topology().vertex(v).restrictions,
                                                      request.vehicle)));
    };
    if (auto slow = traversal.too_slow(*graph, request.vehicle.id)) {
      return error(PlanFailure::invalid_request, std::move(*slow));
    }
    if (!traversal.usable_vertex(request.start)) return restricted(request.start, "start vertex");
    for (std::size_t k = 0; k < request.stops.size(); ++k) {
      if (!traversal.usable_vertex(request.stops[k].vertex)) {
        return restricted(request.stops[k].vertex, fmt::format("stop {}", k));
      }
    }
    return std::nullopt;
  }

  /// Sets up one leg per stop with its heuristic table, or says why a stop is out of reach.
  std::optional<PlanError> prepare_legs(const Traversal& traversal, std::uint64_t class_id,
                                        const PlanRequest& request) {
    heuristics.next_request();
    const std::size_t count = request.stops.size();
    legs.resize(count);
    std::vector<DurationNs> leg_time(count);
    for (std::size_t k = 0; k < count; ++k) {
      const EntityIndex from = k == 0 ? request.start : request.stops[k - 1].vertex;
      const EntityIndex to = request.stops[k].vertex;
      Leg& leg = legs[k];
      leg.stop = to;
      leg.dwell = request.stops[k].dwell.value_or(k + 1 == count ? kForever : 0);
      leg.table = &heuristics.table(*graph, class_id, to);
      leg_time[k] = leg.table->distance(*graph, traversal, from);
      if (leg_time[k] == kUnreachable) {
        if (connected(*graph, from, to)) {
          return error(PlanFailure::restricted,
                       fmt::format("every path from {} to {} (stop {}) uses an entity vehicle "
                                   "'{}' may not use (type, payload or size)",
                                   vertex_name(from), vertex_name(to), k, request.vehicle.id));
        }
        return error(PlanFailure::unreachable,
                     fmt::format("no path leads from {} to {} (stop {}) in topology '{}'",
                                 vertex_name(from), vertex_name(to), k, topology().name()));
      }
    }
    // The least time the stops take, counted up to just past the horizon: beyond it no
    // route can be found, and below it the tails below cannot overflow.
    DurationNs least = 0;
    for (std::size_t k = 0; k < count; ++k) {
      const DurationNs dwell = k + 1 < count ? legs[k].dwell : 0;
      least = std::min(least + leg_time[k] + dwell, horizon() + 1);
    }
    if (least > horizon()) {
      return error(PlanFailure::no_window,
                   fmt::format("even on an empty topology the stops take more than the "
                               "horizon of {}: the fastest drive between them and their dwells",
                               time_text(horizon())));
    }
    legs[count - 1].tail = 0;
    for (std::size_t k = count - 1; k-- > 0;) {
      legs[k].tail = legs[k].dwell + leg_time[k + 1] + legs[k + 1].tail;
    }
    return std::nullopt;
  }

  /// An open-ended last stop needs a free window that never ends; without one no search
  /// can succeed, so this is checked first. \return why there is none, if so.
  std::optional<PlanError> check_goal_held(const TimelineSet& timelines,
                                           const PlanRequest& request) {
    const Stop& last = request.stops.back();
    if (last.dwell) return std::nullopt;
    const auto open_ended = [](const std::vector<Interval>& windows) {
      return !windows.empty() && windows.back().end == kForever;
    };
    goal_windows.clear();
    timelines.append_free_windows(last.vertex, request.agent, request.start_time, kForever,
                                  goal_windows);
    if (open_ended(goal_windows)) return std::nullopt;
    const TimeNs from = goal_windows.empty() ? request.start_time : goal_windows.back().end;
    goal_windows.clear();
    timelines.append_free_windows(last.vertex, request.agent, request.start_time, kForever,
                                  goal_windows, false);
    const bool locked = open_ended(goal_windows);
    PlanError failure = error(locked ? PlanFailure::locked : PlanFailure::no_window,
                              fmt::format("the last stop {} is never free for good (open-ended) from {} on: {}",
                                          vertex_name(last.vertex), time_text(from),
                                          forever_blocker_text(topology(), timelines, last.vertex,
                                                               request.agent, from, locked)));
    if (!locked) {
      add_open_ended_holders(timelines, last.vertex, request.agent, failure.blockers);
      sort_unique(failure.blockers);
    }
    return failure;
  }

  /// The agents holding open-ended a vertex of a reservation-free fastest path through the
  /// stops (the start excluded: the vehicle stands there): at each vertex the first usable
  /// arc, in the graph's order, that the leg's heuristic table says keeps to a fastest path.
  std::vector<std::string> blockers_on_free_path(const TimelineSet& timelines,
                                                 const Traversal& traversal,
                                                 const PlanRequest& request) {
    std::vector<std::string> blockers;
    EntityIndex at = request.start;
    for (const Leg& leg : legs) {
      HeuristicTable& table = *leg.table;
      while (at != leg.stop) {
        const DurationNs to_go = table.distance(*graph, traversal, at);
        const auto moves = traversal.adjacency(*graph).out_of(at);
        const auto next = std::find_if(moves.begin(), moves.end(), [&](const Traversal::Move& m) {
          // Moves towards vertices that cannot reach the stop are skipped before the sum
          // (kUnreachable plus a travel time overflows).
          const DurationNs rest = table.distance(*graph, traversal, m.to);
          return rest != kUnreachable && traversal.travel(m.arc) + rest == to_go;
        });
        if (next == moves.end()) break;  // never: prepare_legs found the stop reachable
        at = next->to;
        add_open_ended_holders(timelines, at, request.agent, blockers);
      }
    }
    sort_unique(blockers);
    return blockers;
  }

  /// True when the search could start: a free window of the start vertex begins at the
  /// start time (what the search tests on the windows it reads).
  bool start_free(const TimelineSet& timelines, const PlanRequest& request) {
    start_windows.clear();
    timelines.append_free_windows(request.start, request.agent, request.start_time, kForever,
                                  start_windows);
    return !start_windows.empty() && start_windows.front().start == request.start_time;
  }

  /// True when every leg's stop is reachable from where the leg starts (prepare_legs would
  /// find a reservation-free time for each); false when that is not known.
  bool legs_reachable(const Traversal& traversal, const PlanRequest& request) const {
    EntityIndex from = request.start;
    for (const Stop& stop : request.stops) {
      if (!traversal.mutually_reachable(*graph, from, stop.vertex)) return false;
      from = stop.vertex;
    }
    return true;
  }

  /// Why the start vertex is not free at the start time.
  PlanError blocked_start(const TimelineSet& timelines, const PlanRequest& request) const {
    const std::string& agent = request.agent;
    std::vector<Interval> without_locks;
    timelines.append_free_windows(request.start, agent, request.start_time,
                                  request.start_time + 1, without_locks, false);
    const std::string why = blocker_text(topology(), timelines, request.start, agent,
                                         request.start_time);
    return error(without_locks.empty() ? PlanFailure::no_window : PlanFailure::locked,
                 fmt::format("start vertex {} is not free at {}: {}",
                             vertex_name(request.start), time_text(request.start_time), why));
  }

  /// Explains a search that found nothing (only called then, so it may take its time), or
  /// that was not run because `lock_blame` (a lock on the start or the last stop) rules
  /// every route out. A lock is blamed only where a search without locks finds a route:
  /// otherwise the reservations are, as that search saw them.
  PlanError diagnose(const TimelineSet& timelines, const PlanRequest& request, SearchInput input,
                     const SearchOutcome& outcome, std::optional<PlanError> lock_blame = {}) {
    const EntityIndex goal = request.stops.back().vertex;
    SearchOutcome explained = outcome;
    // Without any lock, a search without locks would find nothing new.
    if (timelines.lock_count() > 0) {
      if (!lock_blame && !outcome.start_free) {
        PlanError blocked = blocked_start(timelines, request);
        if (blocked.reason != PlanFailure::locked) return blocked;
        lock_blame = std::move(blocked);
      }
      input.count_locks = false;
      explained = search.run(input);
      if (explained.found) {
        if (lock_blame) return std::move(*lock_blame);
        return error(PlanFailure::locked,
                     fmt::format("locks block every route to {}; without them it would arrive "
                                 "at {}",
                                 vertex_name(goal), time_text(search.route(input).arrival)));
      }
    }
    if (!explained.start_free) return blocked_start(timelines, request);
    if (explained.horizon_cut) {
      return error(PlanFailure::no_window,
                   fmt::format("no sequence of free windows reaches {} within the horizon of "
                               "{} after {}",
                               vertex_name(goal), time_text(horizon()),
                               time_text(request.start_time)));
    }
    PlanError failure = error(PlanFailure::no_window,
                              fmt::format("other agents' reservations block every route to {} for good",
                                          vertex_name(goal)));
    failure.blockers = blockers_on_free_path(timelines, *input.traversal, request);
    if (!failure.blockers.empty()) {
      failure.message += fmt::format(" (standing in the way: {})", fmt::join(failure.blockers, ", "));
    }
    return failure;
  }

  Result<Route, PlanError> plan(const TimelineSet& timelines, const PlanRequest& request) {
    stats = PlanStats{};
    if (auto bad = check_request(timelines, request)) return unexpected(std::move(*bad));
    const auto [traversal, class_id] = traversals.get(*graph, request.vehicle);
    if (auto bad = check_usable(*traversal, request)) return unexpected(std::move(*bad));
    // A blocked start makes the search fail at once, after the heuristic (about 1 000
    // expansions each on the warehouse map). When the legs are known to be reachable,
    // prepare_legs can fail only as no_window (stops too far apart for the horizon), so the
    // answer of the checks below comes without it (the goal check, then the blocked start)
    // unless that answer blames a lock: a lock is blamed only where a search without locks
    // finds a route (diagnose), which needs the legs.
    if (!start_free(timelines, request) && legs_reachable(*traversal, request)) {
      auto early = check_goal_held(timelines, request);
      if (!early) early = blocked_start(timelines, request);
      if (early->reason != PlanFailure::locked) return unexpected(std::move(*early));
    }
    if (auto bad = prepare_legs(*traversal, class_id, request)) {
      return unexpected(std::move(*bad));
    }
    auto goal_held = check_goal_held(timelines, request);
    if (goal_held && goal_held->reason != PlanFailure::locked) {
      return unexpected(std::move(*goal_held));
    }
    SearchInput input;
    input.graph = graph.get();
    input.traversal = traversal;
    input.timelines = &timelines;
    input.agent = request.agent;
    input.start = request.start;
    input.start_time = request.start_time;
    input.legs = legs;
    input.deadline = request.start_time + horizon();
    input.quick_proof_after = options.quick_proof_after;
    input.quick_proof_budget = options.quick_proof_budget;
    input.floor_proof_after = options.floor_proof_after;
    input.floor_proof_budget = options.floor_proof_budget;
    input.shut_in_after = options.shut_in_after;
    input.shut_in_region = options.shut_in_region;
    input.shut_in_budget = options.shut_in_budget;
    if (goal_held) {  // locked for good: confirmed, or not, by a search without locks
      return unexpected(diagnose(timelines, request, input, SearchOutcome{}, std::move(goal_held)));
    }
    const SearchOutcome outcome = search.run(input);
    stats = search.stats();
    if (!outcome.found) return unexpected(diagnose(timelines, request, input, outcome));
    return search.route(input);
  }
};

Planner::Planner(std::shared_ptr<const RoutingGraph> graph, PlannerOptions options)
    : impl_(std::make_unique<Impl>(std::move(graph), options)) {}
Planner::~Planner() = default;
Planner::Planner(Planner&&) noexcept = default;
Planner& Planner::operator=(Planner&&) noexcept = default;

const RoutingGraph& Planner::graph() const noexcept { return *impl_->graph; }

const PlanStats& Planner::last_stats() const noexcept { return impl_->stats; }

Result<Route, PlanError> Planner::plan(const TimelineSet& timelines, const PlanRequest& request) {
  return impl_->plan(timelines, request);
}

Result<Route, PlanError> Planner::plan_and_reserve(TimelineSet& timelines,
                                                   const PlanRequest& request,
                                                   topology::RouteId route) {
  auto planned = impl_->plan(timelines, request);
  if (!planned) return planned;
  if (auto reserved = timelines.reserve(request.agent, route, planned->steps); !reserved) {
    return unexpected(error(PlanFailure::conflict,
                            fmt::format("route {} of agent {} was planned but not reserved: {}",
                                        route, request.agent, reserved.error().message)));
  }
  return planned;
}

}  // namespace drover::carp
