#pragma once
// Context-Aware Route Planning (ter Mors et al.): the earliest-arrival route through free
// time windows of vertices and edges, around the reservations and locks in a TimelineSet.

#include <memory>

#include "drover/carp/route.hpp"
#include "drover/carp/routing_graph.hpp"
#include "drover/topology/timeline.hpp"

namespace drover::carp {

struct PlannerOptions {
  /// Routes must reach every stop within start_time + horizon (the search gives up on
  /// later windows and reports no_window). > 0; longer than kLongestDuration counts as it.
  DurationNs horizon = 3600 * kNsPerSecond;
  /// How many heuristic tables (one per goal and vehicle class) are kept between calls.
  std::size_t heuristic_tables = 64;
  /// After expanding this many states keyed by the arrival floor (the earliest the last
  /// stop can be entered and held), a search tries a quick proof that no route arrives that
  /// early, to raise the floor (docs/carp.md): at most quick_proof_budget backward states,
  /// with how early a route can reach a vertex bounded by the heuristic alone, so that
  /// trying costs almost nothing. Once per floor; 0: never. Any value gives the same
  /// arrivals; 64 and 16 paid off best on the benchmark's maps (docs/benchmarks.md).
  std::size_t quick_proof_after = 64;
  std::size_t quick_proof_budget = 16;
  /// After expanding this many states keyed by the arrival floor, a search tries a full
  /// proof (with the exact earliest times from the start, a forward table); four times as
  /// many before each further try. A full proof that reaches the start has found the route
  /// instead. Any value >= 1 gives the same arrivals; 256 paid off best on the benchmark's
  /// maps since proofs find routes (192, 384, 512 tried; docs/benchmarks.md).
  std::size_t floor_proof_after = 256;
  /// How many backward states such a proof may visit before it gives up; four times as many
  /// at each further try. Any value >= 1 gives the same arrivals; 128 paid off best (64,
  /// 192, 256, 512, 1024 tried).
  std::size_t floor_proof_budget = 128;
  /// After expanding this many states, a search for one open-ended stop checks whether
  /// the stop is shut in: whether the entities that some time become free for good
  /// connect it with at most shut_in_region vertices, the start not among them (agents
  /// parked around it for good). If so, it tries to prove, with at most shut_in_budget
  /// backward states, that no route arrives at all, and fails at once if that holds
  /// (warehouse N = 400: two such searches expanded 10 000 states each before). Once per
  /// search; 0: never. Any values give the same outcomes (docs/carp.md).
  std::size_t shut_in_after = 256;
  std::size_t shut_in_region = 16;
  std::size_t shut_in_budget = 4096;
};

/// What the search of the last Planner::plan call did (for tests and measurements).
struct PlanStats {
  /// The arrival floor the search ended with: no route arrives earlier (kForever when a
  /// proof showed that none ever arrives). 0 when no search ran.
  TimeNs arrival_floor = 0;
  std::size_t floor_proofs = 0;  ///< backward proofs tried
  std::size_t floor_raises = 0;  ///< proofs that raised the floor
  std::size_t proof_routes = 0;  ///< 1 when a proof found the route (it reached the start)
  std::size_t expanded = 0;      ///< states taken from the open list (stale entries aside)
  /// 1 when the search found its last stop shut in (see PlannerOptions::shut_in_after) and
  /// tried to prove that no route arrives at all.
  std::size_t shut_in_proofs = 0;
  std::size_t shut_in_refusals = 0;  ///< 1 when that proof held and ended the search
};

/// The route planner of a routing agent. It keeps search memory and heuristic tables
/// between calls, so one Planner serves many requests; it is not thread-safe (one per
/// thread). The graph (and its topology) must outlive it.
///
/// Model (docs/carp.md): driving arc a takes travel(a) = length / min(vehicle max speed,
/// speed limit of a); vertices take no time. Passing from one entity to the next, the
/// vehicle occupies both for the clearance time length_vehicle / speed of the edge
/// involved, so consecutive step windows overlap by it. The vehicle may wait on any
/// entity while its free window lasts.
class Planner {
 public:
  explicit Planner(std::shared_ptr<const RoutingGraph> graph, PlannerOptions options = {});
  ~Planner();
  Planner(Planner&&) noexcept;
  Planner& operator=(Planner&&) noexcept;

  /// A test route: plans on `timelines` and reserves nothing.
  /// \param timelines  the timelines of every entity of the graph's topology
  /// \return the route arriving earliest at the last stop (stops in order, each held for
  ///         its dwell, the last one open-ended unless it has a dwell), or why there is
  ///         none. Never an empty route.
  Result<Route, PlanError> plan(const topology::TimelineSet& timelines,
                                const PlanRequest& request);

  /// A real route: plan() and then reserve it in `timelines` as (agent, route), all or
  /// nothing. On error nothing is reserved.
  Result<Route, PlanError> plan_and_reserve(topology::TimelineSet& timelines,
                                            const PlanRequest& request,
                                            topology::RouteId route);

  const RoutingGraph& graph() const noexcept;

  /// What the search of the last plan (or plan_and_reserve) call did; only the first search
  /// counts, not the searches that explain a failure.
  const PlanStats& last_stats() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drover::carp
