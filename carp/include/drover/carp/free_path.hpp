#pragma once
// A plain A* on the routing graph that ignores reservations and locks: the fastest path a
// vehicle could take on an empty topology. It is the baseline `drover bench plan`
// measures the planner against, and a lower bound of every planned route's travel time.

#include <memory>
#include <vector>

#include "drover/carp/routing_graph.hpp"
#include "drover/carp/vehicle.hpp"
#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"

namespace drover::carp {

struct FreePath {
  std::vector<topology::EntityIndex> vertices;  ///< from start to goal, inclusive
  DurationNs travel_time = 0;                   ///< same travel times as the Planner
  double distance = 0;                          ///< metres
};

/// Forward A* with the straight-line heuristic (straightness * distance / top speed), a
/// binary heap and search memory reused between calls. Honours the vehicle's speed and
/// restrictions like the Planner does. Not thread-safe.
class FreePathSearch {
 public:
  explicit FreePathSearch(std::shared_ptr<const RoutingGraph> graph);
  ~FreePathSearch();

  /// \return the fastest path, or not_found for a bad vertex, invalid_argument for a bad
  ///         profile, unavailable when the vehicle cannot reach the goal.
  Result<FreePath> find(const VehicleProfile& vehicle, topology::EntityIndex start,
                        topology::EntityIndex goal);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drover::carp
