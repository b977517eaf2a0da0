#pragma once
// The topology as the planner walks it: flat arrays built once per Topology.
//
// Nodes are the vertices (node = vertex EntityIndex) and the arcs, one per drivable
// direction of an edge (a bidirectional edge gives two arcs over the same entity).
// Arcs are sorted by their from-vertex, so the arcs leaving a vertex are one index range.

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "drover/topology/model.hpp"

namespace drover::carp {

using ArcIndex = std::uint32_t;

/// One drivable direction of an edge.
struct Arc {
  topology::EntityIndex edge = topology::kNoEntity;  ///< the edge entity
  topology::EntityIndex from = topology::kNoEntity;  ///< vertex
  topology::EntityIndex to = topology::kNoEntity;    ///< vertex
  double length = 0;       ///< metres
  /// min of the edge's max speed, its restriction max speed and the restriction max speeds
  /// of both end vertices (a vertex's limit applies while passing it). m/s.
  double speed_limit = 0;
};

class RoutingGraph {
 public:
  /// Builds the arrays. The topology must outlive the graph.
  explicit RoutingGraph(const topology::Topology& topology);

  const topology::Topology& topology() const noexcept { return *topology_; }
  std::size_t vertex_count() const noexcept { return x_.size(); }
  std::size_t arc_count() const noexcept { return arcs_.size(); }

  const Arc& arc(ArcIndex index) const { return arcs_[index]; }
  /// Arcs leaving `vertex`: indices [first, last). \pre vertex < vertex_count()
  ArcIndex arcs_begin(topology::EntityIndex vertex) const { return out_begin_[vertex]; }
  ArcIndex arcs_end(topology::EntityIndex vertex) const { return out_begin_[vertex + 1]; }
  /// Arcs entering `vertex`. \pre vertex < vertex_count()
  std::span<const ArcIndex> arcs_into(topology::EntityIndex vertex) const {
    return {in_arcs_.data() + in_begin_[vertex], in_arcs_.data() + in_begin_[vertex + 1]};
  }

  double x(topology::EntityIndex vertex) const { return x_[vertex]; }
  double y(topology::EntityIndex vertex) const { return y_[vertex]; }
  /// Straight-line distance between two vertices, metres. The square root of the sum of
  /// squares rather than std::hypot, whose guards against overflow (coordinates in metres
  /// are far from it) took a quarter of the A* baseline's time (docs/benchmarks.md).
  double straight_distance(topology::EntityIndex a, topology::EntityIndex b) const {
    const double dx = x_[a] - x_[b], dy = y_[a] - y_[b];
    return std::sqrt(dx * dx + dy * dy);
  }
  /// The largest s such that every arc's length >= s * straight distance of its ends
  /// (at most 1): s * straight_distance is a lower bound of the driven distance.
  double straightness() const noexcept { return straightness_; }
  /// The highest speed limit of any arc (m/s), 0 when there are no arcs.
  double top_speed_limit() const noexcept { return top_speed_limit_; }

 private:
  const topology::Topology* topology_;
  std::vector<double> x_, y_;
  std::vector<Arc> arcs_;
  std::vector<ArcIndex> out_begin_;  // vertex_count + 1
  std::vector<ArcIndex> in_begin_;   // vertex_count + 1
  std::vector<ArcIndex> in_arcs_;
  double straightness_ = 1.0;
  double top_speed_limit_ = 0;
};

}  // namespace drover::carp
