#include "drover/ran/validation.hpp"

#include <algorithm>
#include <cmath>

#include <boost/geometry/algorithms/covered_by.hpp>
#include <fmt/format.h>

namespace drover::ran {

namespace {

Unexpected<Rejection> reject(const char* code, std::string reason) {
  return unexpected(Rejection{code, std::move(reason)});
}

double distance(double ax, double ay, double bx, double by) { return std::hypot(ax - bx, ay - by); }

/// Distance from (px, py) to the segment a-b.
double distance_to_segment(double px, double py, const topology::Point& a, const topology::Point& b) {
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  const double squared = dx * dx + dy * dy;
  const double t =
      squared > 0 ? std::clamp(((px - a.x()) * dx + (py - a.y()) * dy) / squared, 0.0, 1.0) : 0.0;
  return distance(px, py, a.x() + t * dx, a.y() + t * dy);
}

}  // namespace

CommandCheck validate(const MoveCommand& command) {
  using namespace rejection_code;
  if (command.id.empty()) return reject(kMalformed, "move: id is empty");
  const std::string where = fmt::format("move '{}'", command.id);
  if (command.target_vertex.empty()) {
    return reject(kMalformed, where + ": target_vertex is empty");
  }
  if (!std::isfinite(command.target.x) || !std::isfinite(command.target.y) ||
      (command.target.theta && !std::isfinite(*command.target.theta))) {
    return reject(kMalformed, where + ": target pose is not finite");
  }
  if (!std::isfinite(command.max_speed) || command.max_speed <= 0) {
    return reject(kInvalidSpeed,
                  fmt::format("{}: max_speed {} is not a positive speed", where, command.max_speed));
  }
  if (command.area.empty()) return reject(kMalformed, where + ": motion area is empty");
  for (std::size_t i = 0; i < command.area.size(); ++i) {
    const auto& ring = command.area[i].outer();
    // A closed triangle has 4 points; an open one 3.
    if (ring.size() < 3) {
      return reject(kMalformed, fmt::format("{}: area part {} has fewer than 3 corners", where, i));
    }
    const bool finite = std::all_of(ring.begin(), ring.end(), [](const topology::Point& p) {
      return std::isfinite(p.x()) && std::isfinite(p.y());
    });
    if (!finite) {
      return reject(kMalformed, fmt::format("{}: area part {} has a non-finite corner", where, i));
    }
  }
  return {};
}

CommandCheck validate(const ActionCommand& command) {
  using namespace rejection_code;
  if (command.id.empty()) return reject(kMalformed, "action: id is empty");
  if (command.kind == ActionKind::custom && command.name.empty()) {
    return reject(kMalformed, fmt::format("action '{}': a custom action needs a name", command.id));
  }
  return {};
}

CommandCheck check_against_topology(const MoveCommand& command, const topology::Topology& topology,
                                    const Pose& start, double position_tolerance) {
  using namespace rejection_code;
  const std::string where = fmt::format("move '{}'", command.id);
  const auto target = topology.find(command.target_vertex);
  if (!target || !topology.is_vertex(*target)) {
    return reject(kUnknownVertex,
                  fmt::format("{}: target_vertex '{}' is not a vertex of topology '{}'", where,
                              command.target_vertex, topology.name()));
  }
  const topology::Vertex& vertex = topology.vertex(*target);
  if (distance(command.target.x, command.target.y, vertex.position.x(), vertex.position.y()) >
      position_tolerance) {
    return reject(kMalformed,
                  fmt::format("{}: target ({}, {}) is not the position ({}, {}) of vertex '{}'",
                              where, command.target.x, command.target.y, vertex.position.x(),
                              vertex.position.y(), vertex.id));
  }
  const bool start_at_target =
      distance(start.x, start.y, vertex.position.x(), vertex.position.y()) <= position_tolerance;
  if (command.edge.empty()) {
    if (start_at_target) return {};
    return reject(kEdgeMismatch,
                  fmt::format("{}: no edge given, but the move starts at ({}, {}), not at '{}'",
                              where, start.x, start.y, vertex.id));
  }
  const auto edge_index = topology.find(command.edge);
  if (!edge_index || !topology.is_edge(*edge_index)) {
    return reject(kUnknownEdge, fmt::format("{}: edge '{}' is not an edge of topology '{}'", where,
                                            command.edge, topology.name()));
  }
  const topology::Edge& edge = topology.edge(*edge_index);
  std::optional<topology::EntityIndex> from;
  if (edge.to == *target) {
    from = edge.from;
  } else if (edge.bidirectional && edge.from == *target) {
    from = edge.to;
  }
  if (!from) {
    return reject(kEdgeMismatch,
                  fmt::format("{}: edge '{}' does not lead to vertex '{}'", where, edge.id, vertex.id));
  }
  const topology::Vertex& origin = topology.vertex(*from);
  // A vehicle that braked to a stop a little past a vertex (a cancel) stands on it as far as
  // its commander can tell (inside its footprint), but on the edge it came by: moves from
  // that vertex over another edge start there. Whether the way from there to the target
  // stays inside the motion area is the driver's check (outside_area).
  const bool on_edge =
      distance_to_segment(start.x, start.y, origin.position, vertex.position) <= position_tolerance;
  if (!on_edge &&
      !boost::geometry::covered_by(topology::Point(start.x, start.y), topology.footprint(*from))) {
    return reject(kEdgeMismatch,
                  fmt::format("{}: edge '{}' runs from vertex '{}' ({}, {}), but the move starts "
                              "at ({}, {}), off the edge and outside the vertex's footprint",
                              where, edge.id, origin.id, origin.position.x(), origin.position.y(),
                              start.x, start.y));
  }
  double edge_limit = edge.max_speed;
  if (edge.restrictions.max_speed) edge_limit = std::min(edge_limit, *edge.restrictions.max_speed);
  if (command.max_speed > edge_limit + 1e-9) {
    return reject(kInvalidSpeed, fmt::format("{}: max_speed {} exceeds edge '{}' limit {}", where,
                                             command.max_speed, edge.id, edge_limit));
  }
  return {};
}

}  // namespace drover::ran
