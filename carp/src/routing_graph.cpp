#include "drover/carp/routing_graph.hpp"

#include <algorithm>
#include <cmath>

namespace drover::carp {

using topology::EntityIndex;

namespace {

double speed_limit_of(const topology::Topology& topology, const topology::Edge& edge) {
  double limit = edge.max_speed;
  const auto lower = [&limit](const std::optional<double>& value) {
    if (value) limit = std::min(limit, *value);
  };
  lower(edge.restrictions.max_speed);
  lower(topology.vertex(edge.from).restrictions.max_speed);
  lower(topology.vertex(edge.to).restrictions.max_speed);
  return limit;
}

}  // namespace

RoutingGraph::RoutingGraph(const topology::Topology& topology) : topology_(&topology) {
  const std::size_t vertices = topology.vertex_count();
  x_.resize(vertices);
  y_.resize(vertices);
  out_begin_.assign(vertices + 1, 0);
  for (EntityIndex v = 0; v < vertices; ++v) {
    x_[v] = topology.vertex(v).position.x();
    y_[v] = topology.vertex(v).position.y();
    for (const topology::Move& move : topology.moves_from(v)) {
      const topology::Edge& edge = topology.edge(move.edge);
      arcs_.push_back(Arc{move.edge, v, move.to, edge.length, speed_limit_of(topology, edge)});
    }
    out_begin_[v + 1] = static_cast<ArcIndex>(arcs_.size());
  }

  in_begin_.assign(vertices + 1, 0);
  for (const Arc& arc : arcs_) ++in_begin_[arc.to + 1];
  for (std::size_t v = 0; v < vertices; ++v) in_begin_[v + 1] += in_begin_[v];
  in_arcs_.resize(arcs_.size());
  std::vector<ArcIndex> fill(in_begin_.begin(), in_begin_.end() - 1);
  for (ArcIndex a = 0; a < arcs_.size(); ++a) in_arcs_[fill[arcs_[a].to]++] = a;

  for (const Arc& arc : arcs_) {
    top_speed_limit_ = std::max(top_speed_limit_, arc.speed_limit);
    const double straight = straight_distance(arc.from, arc.to);
    if (straight > 0) straightness_ = std::min(straightness_, arc.length / straight);
  }
}

}  // namespace drover::carp
