#pragma once
// What a route request asks for and what the planner answers.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "drover/carp/vehicle.hpp"
#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/topology/timeline.hpp"

namespace drover::carp {

/// The longest dwell, the longest sum of a request's dwells, the longest horizon (a longer
/// one is cut to it) and the longest travel time of a path the planner takes: an eighth of
/// the TimeNs range, about 36 years. With start times up to kLatestTime (half the range, in
/// drover/common/clock.hpp) no sum of the planner's times overflows: a start time and four
/// such durations at most.
inline constexpr DurationNs kLongestDuration = kForever / 8;
/// The most stops one request may have: a search keeps a little for every (stop, vertex)
/// pair, 8 bytes, so 1 024 stops on a map of 100 000 vertices take 800 MB.
inline constexpr std::size_t kMaxStops = 1024;

/// A vertex the route must reach, in request order.
struct Stop {
  topology::EntityIndex vertex = topology::kNoEntity;
  /// How long the vehicle stays after arriving (>= 0). For every stop but the last, absent
  /// means 0. For the last stop, absent means the vertex is held open-ended (until the
  /// agent's next route); given, it must be > 0 and the vertex is held [arrival, arrival +
  /// dwell).
  std::optional<DurationNs> dwell;
};

/// A route request: one call plans the whole sequence of stops.
struct PlanRequest {
  topology::AgentId agent;   ///< whose route; the agent's own reservations never block it
  VehicleProfile vehicle;
  topology::EntityIndex start = topology::kNoEntity;  ///< a vertex; held from start_time
  TimeNs start_time = 0;
  std::vector<Stop> stops;   ///< at least one, at most kMaxStops
};

/// A planned route.
///
/// Guarantees: steps alternate vertex, edge, vertex, ..., starting at the request's start
/// and ending at its last stop; each edge joins the vertices around it and is driven in an
/// allowed direction. steps[0].window.start is the start time; consecutive windows overlap
/// by the clearance time of the edge between them (the vehicle spans both while it
/// passes); no window overlaps another agent's reservation on the step's entity or its
/// conflict set, nor a lock there. The last window ends at kForever for an open-ended stop.
struct Route {
  std::vector<topology::RouteStep> steps;
  std::vector<std::size_t> stop_steps;   ///< per stop, the index of its step in `steps`
  std::vector<TimeNs> stop_arrivals;     ///< per stop, when the vehicle arrives there
  double distance = 0;                   ///< metres driven
  TimeNs arrival = 0;                    ///< arrival at the last stop (earliest possible)
  DurationNs travel_time = 0;            ///< arrival - start_time (driving and waiting)
};

/// Why no route was returned.
enum class PlanFailure {
  invalid_request,  ///< malformed request: unknown vertex, bad vehicle, no stops, bad dwell
  unreachable,      ///< no path in the graph at all, whatever the time
  restricted,       ///< paths exist, but not for this vehicle (type, payload, size)
  locked,           ///< locks block every route that reservations alone would allow
  no_window,        ///< other agents' reservations leave no sequence of free windows
                    ///< reaching the stops within the planning horizon
  conflict,         ///< a real route could not be reserved (the timelines disagreed)
};

/// Stable lower-case name ("no_window", ...), as printed by tools.
const char* to_string(PlanFailure failure) noexcept;

struct PlanError {
  PlanFailure reason = PlanFailure::invalid_request;
  std::string message;  ///< names the vertices and times involved
  /// For a no_window failure that lasts for good: the agents whose open-ended holds (a
  /// vehicle standing on its last stop, idle or waiting for work) stand in the way, on the
  /// last stop or along the reservation-free fastest path to it. The route may exist once
  /// they move: a logical agent asks them to make way. Sorted, without duplicates; empty
  /// for every other failure.
  std::vector<std::string> blockers;
};

/// The library-wide error for a planning failure (code chosen by reason).
Error to_error(const PlanError& error);

}  // namespace drover::carp
