#include "agents/logical_agent/src/route_tracker.hpp"

#include <algorithm>

#include <boost/geometry.hpp>

#include "agents/logical_agent/src/travel_time.hpp"

namespace drover::logical_agent {

namespace bg = boost::geometry;

RouteTracker::RouteTracker(std::shared_ptr<const topology::Topology> topology, topology::RouteId route,
                           std::vector<topology::RouteStep> steps)
    : topology_(std::move(topology)), route_(route), steps_(std::move(steps)) {}

void RouteTracker::shift(std::size_t from_step, DurationNs by) {
  if (from_step >= steps_.size()) return;
  auto moved = [by](TimeNs t) { return t == kForever ? t : t + by; };
  steps_[from_step].window.end = moved(steps_[from_step].window.end);
  for (std::size_t i = from_step + 1; i < steps_.size(); ++i) {
    steps_[i].window.start = moved(steps_[i].window.start);
    steps_[i].window.end = moved(steps_[i].window.end);
  }
}

std::optional<std::size_t> RouteTracker::next_to_allocate(std::size_t position_step, std::size_t lookahead) const {
  if (allocated_ >= steps_.size()) return std::nullopt;
  // `lookahead` vertices ahead, with the edges leading to them.
  if (allocated_ > position_step + 2 * lookahead) return std::nullopt;
  return allocated_;
}

std::optional<std::size_t> RouteTracker::next_move() const {
  const std::size_t edge = commanded_ + 1;
  if (edge + 1 >= steps_.size() || edge + 1 >= allocated_) return std::nullopt;
  return edge;
}

ran::MoveCommand move_along(const topology::Topology& world, topology::EntityIndex edge_index,
                            topology::EntityIndex target, const std::string& id, double max_speed) {
  const auto& edge = world.edge(edge_index);
  const auto& vertex = world.vertex(target);
  ran::MoveCommand move;
  move.id = id;
  move.target_vertex = world.id(target);
  move.target = ran::TargetPose{vertex.position.x(), vertex.position.y(), vertex.orientation};
  move.edge = edge.id;
  move.max_speed = std::min(max_speed, edge.max_speed);
  if (edge.restrictions.max_speed) move.max_speed = std::min(move.max_speed, *edge.restrictions.max_speed);
  const auto other_end = edge.from == target ? edge.to : edge.from;
  move.area = {world.footprint(other_end), world.footprint(edge_index), world.footprint(target)};
  return move;
}

ran::MoveCommand RouteTracker::command_move(std::size_t edge_step, const std::string& id, double max_speed) {
  auto move = move_along(*topology_, steps_.at(edge_step).entity, steps_.at(edge_step + 1).entity, id, max_speed);
  commanded_ = edge_step + 1;
  return move;
}

double RouteTracker::remaining_distance(const topology::Point& position, std::size_t vertex_step) const {
  const auto& world = *topology_;
  if (vertex_step <= reached_) return 0;
  const std::size_t next = reached_ + 2;
  double distance = bg::distance(position, world.vertex(steps_.at(next).entity).position);
  for (std::size_t edge = next + 1; edge < vertex_step; edge += 2) {
    distance += world.edge(steps_.at(edge).entity).length;
  }
  return distance;
}

std::optional<DurationNs> RouteTracker::lateness(const topology::Point& position, double speed,
                                                 const carp::VehicleProfile& vehicle, TimeNs now) const {
  if (arrived()) return std::nullopt;
  const std::size_t next = reached_ + 2;
  const TimeNs estimated = now + drive_time(remaining_distance(position, next), speed, vehicle);
  return estimated - steps_.at(next).window.start;
}

}  // namespace drover::logical_agent
