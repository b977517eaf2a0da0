#pragma once
// What the routing graph means for one vehicle class: travel and clearance times per arc,
// and which vertices and arcs it may use. Computed once per class and cached.

#include <compare>
#include <cstdint>
#include <algorithm>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "drover/carp/route.hpp"
#include "drover/carp/routing_graph.hpp"
#include "drover/carp/vehicle.hpp"
#include "drover/common/clock.hpp"

namespace drover::carp {

/// "Never": the travel time of an unreachable vertex.
inline constexpr DurationNs kUnreachable = kForever;

class Traversal {
 public:
  Traversal(const RoutingGraph& graph, const VehicleProfile& vehicle);

  /// True when two profiles drive the graph alike (same speed, type, size and payload).
  static bool same_class(const VehicleProfile& a, const VehicleProfile& b);

  /// Time to drive the arc: length / min(max speed, arc speed limit), rounded to the
  /// nearest ns and at least 1 ns.
  DurationNs travel(ArcIndex arc) const { return travel_[arc]; }
  /// How long the vehicle spans an end vertex and the arc while passing between them:
  /// vehicle length / the same speed, rounded up.
  DurationNs clearance(ArcIndex arc) const { return clearance_[arc]; }
  /// The shortest travel() of a usable arc (1 ns when none is usable).
  DurationNs min_travel() const { return min_travel_; }

  /// The most a travel() or clearance() may take on a graph of `vertex_count` vertices:
  /// then no path's travel time (at most one arc per vertex) passes kLongestDuration, and the
  /// searches' sums of times and durations stay far from overflowing.
  static DurationNs max_arc_time(std::size_t vertex_count) {
    return kLongestDuration / static_cast<DurationNs>(std::max<std::size_t>(vertex_count, 1));
  }
  /// Why vehicle `vehicle_id` (of this class) cannot be planned for on `graph` (the one
  /// the traversal was built for), if so: on some arc it may drive, its travel or clearance
  /// would pass max_arc_time (a vehicle far too slow, or too long). Such an arc's times are
  /// clipped to that bound, so a search must refuse the vehicle rather than use them.
  std::optional<std::string> too_slow(const RoutingGraph& graph,
                                      const std::string& vehicle_id) const;
  /// Every usable arc takes the same time (a grid with one speed): shortest paths by time
  /// are shortest by arc count.
  bool uniform() const { return uniform_; }
  bool usable_vertex(topology::EntityIndex vertex) const { return usable_vertex_[vertex] != 0; }
  /// The vehicle may drive the arc: its edge and its destination vertex allow it.
  bool usable_arc(ArcIndex arc) const { return usable_arc_[arc] != 0; }

  /// A lower bound of the travel time between two vertices, consistent with travel():
  /// lower_bound(a, c) <= travel(arc a->b) + lower_bound(b, c) for every arc.
  DurationNs lower_bound(const RoutingGraph& graph, topology::EntityIndex a,
                         topology::EntityIndex b) const {
    return static_cast<DurationNs>(ns_per_metre_ * graph.straight_distance(a, b));
  }

  const VehicleProfile& vehicle() const noexcept { return vehicle_; }

  /// How long a move takes: its travel() and clearance().
  struct Timing {
    DurationNs travel;
    DurationNs clearance;
    friend auto operator<=>(const Timing&, const Timing&) = default;
  };
  /// A usable arc into a vertex from a usable one, as the backward searches follow it (the
  /// heuristic's, the floor proofs', the shut-in check's): what they read, in 12 bytes.
  struct Hop {
    std::uint32_t timing;  ///< in Adjacency::timings
    topology::EntityIndex from;
    topology::EntityIndex edge;
  };
  /// A usable arc out of a usable vertex, with what a search needs to drive it: 16 bytes,
  /// four to a cache line, its times (few distinct pairs on most maps) in a table apart.
  /// An expansion reads its vertex's moves, a cache miss more often than not after a
  /// reserve: bench plan, planner L2 misses -12 % at random N = 200 and -7 % at warehouse
  /// N = 400 against 32-byte moves with their times inline (callgrind; instructions +1 %),
  /// ratio to A* about -6 % at warehouse N = 400 (alternated runs).
  struct Move {
    std::uint32_t timing;  ///< in Adjacency::timings
    ArcIndex arc;
    topology::EntityIndex edge;
    topology::EntityIndex to;
  };
  /// The usable arcs of every vertex in flat arrays, for the searches' inner loops: one
  /// contiguous read per vertex instead of the arcs, their times and their usability.
  struct Adjacency {
    /// Up to this degree the padded lists below are kept (grids have 4 or 8).
    static constexpr std::uint32_t kMaxPaddedDegree = 8;
    std::vector<std::uint32_t> into_first, out_first;  // per vertex, and one past the last
    std::vector<Hop> into;
    std::vector<Move> out;
    std::vector<Timing> timings;  // the distinct times of the moves
    const Timing& timing(const Move& move) const { return timings[move.timing]; }
    const Timing& timing(const Hop& hop) const { return timings[hop.timing]; }
    // The vertices alone, in the order of `into` and `out`: what a breadth-first search
    // reads (a quarter and a tenth of the bytes).
    std::vector<topology::EntityIndex> into_from, out_to;
    /// The most arcs into or out of any vertex, when at most kMaxPaddedDegree; else 0.
    std::uint32_t padded_degree = 0;
    /// into_from and out_to again, each vertex's padded to padded_degree entries with the
    /// vertex count, whose label a DistanceTable keeps closed: a breadth-first search's
    /// loop over them runs the same number of times for every vertex, which the processor
    /// predicts, where the exit of a loop over a vertex's own arcs was mispredicted (bench
    /// plan, in-process A/B: ratio to A* -3 % at random N = 200 and 400).
    std::vector<topology::EntityIndex> padded_into_from, padded_out_to;
    std::span<const Hop> into_of(topology::EntityIndex v) const {
      return {into.data() + into_first[v], into.data() + into_first[v + 1]};
    }
    /// None when `v` is not usable.
    std::span<const Move> out_of(topology::EntityIndex v) const {
      return {out.data() + out_first[v], out.data() + out_first[v + 1]};
    }
    /// The `from` of into_of(v).
    std::span<const topology::EntityIndex> sources_of(topology::EntityIndex v) const {
      return {into_from.data() + into_first[v], into_from.data() + into_first[v + 1]};
    }
    /// The `to` of out_of(v).
    std::span<const topology::EntityIndex> targets_of(topology::EntityIndex v) const {
      return {out_to.data() + out_first[v], out_to.data() + out_first[v + 1]};
    }
    /// sources_of(v), then the vertex count up to padded_degree. \pre padded_degree > 0
    std::span<const topology::EntityIndex> padded_sources_of(topology::EntityIndex v) const {
      return {padded_into_from.data() + std::size_t{v} * padded_degree, padded_degree};
    }
    /// targets_of(v), then the vertex count up to padded_degree. \pre padded_degree > 0
    std::span<const topology::EntityIndex> padded_targets_of(topology::EntityIndex v) const {
      return {padded_out_to.data() + std::size_t{v} * padded_degree, padded_degree};
    }
  };
  /// Built on the first call (only the planner asks, not FreePathSearch).
  const Adjacency& adjacency(const RoutingGraph& graph) const {
    if (adjacency_.into_first.empty()) build_adjacency(graph);
    return adjacency_;
  }

  /// True when `a` and `b` lie in one strongly connected component of the usable arcs, so
  /// that the vehicle can drive from either to the other (reservations aside). False says
  /// nothing: b may still be reachable from a.
  /// The components are found on the first call (only the planner asks; FreePathSearch,
  /// the benchmark's baseline, keeps traversals of its own and never pays for them).
  bool mutually_reachable(const RoutingGraph& graph, topology::EntityIndex a,
                          topology::EntityIndex b) const {
    if (a == b) return true;
    if (component_.empty()) find_components(graph);
    return component_[a] == component_[b];
  }

 private:
  /// Fills component_ (Kosaraju, iterative) over the usable arcs.
  void find_components(const RoutingGraph& graph) const;
  void build_adjacency(const RoutingGraph& graph) const;

  VehicleProfile vehicle_;
  std::vector<DurationNs> travel_;
  std::vector<DurationNs> clearance_;
  std::vector<std::uint8_t> usable_vertex_;
  std::vector<std::uint8_t> usable_arc_;
  // Per vertex: its strongly connected component; empty until mutually_reachable needs it
  // (a cache: a traversal is used by one planner, on one thread).
  mutable std::vector<std::uint32_t> component_;
  mutable Adjacency adjacency_;  // empty until adjacency() needs it (a cache, as component_)
  double ns_per_metre_ = 0;
  // The arc whose travel or clearance passes max_arc_time by the most, if any, and that
  // time in seconds.
  struct SlowArc {
    ArcIndex arc;
    double seconds;
  };
  std::optional<SlowArc> too_slow_arc_;
  DurationNs min_travel_ = 1;
  bool uniform_ = true;
};

/// The traversals of the vehicle classes seen lately (least recently used dropped first).
/// Each class gets a unique id, never reused, that keys its heuristic tables.
class TraversalCache {
 public:
  explicit TraversalCache(std::size_t capacity) : capacity_(capacity < 1 ? 1 : capacity) {}

  struct Found {
    const Traversal* traversal;
    std::uint64_t class_id;
  };
  /// The traversal of the vehicle's class, built on first use. Stays valid until `capacity`
  /// other classes have been asked for.
  Found get(const RoutingGraph& graph, const VehicleProfile& vehicle);

 private:
  struct Entry {
    std::unique_ptr<Traversal> traversal;
    std::uint64_t class_id = 0;
    std::uint64_t last_used = 0;
  };
  std::size_t capacity_;
  std::vector<Entry> entries_;
  std::uint64_t next_class_id_ = 1;
  std::uint64_t clock_ = 0;
};

}  // namespace drover::carp
