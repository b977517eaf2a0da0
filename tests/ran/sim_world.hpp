#pragma once
// A small world for the RAN tests: a topology (built with TopologyBuilder, default
// footprints: 1 m vertex squares, 1 m wide edges), moves whose motion area is the union of
// the footprints of the start vertex, the edge and the target vertex (what a logical agent
// allocates), and helpers that step a vehicle until something happens.
//
//   A(0,0) --ab-- B(5,0) --bc-- C(10,0)
//                                 |cd
//                               D(10,5) --de-- E(13,9)      (de is directed d -> e)

#include <functional>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "drover/ran/sim_vehicle.hpp"
#include "drover/topology/topology_builder.hpp"

namespace drover::ran::test {

inline std::shared_ptr<const topology::Topology> world() {
  topology::TopologyBuilder builder("ran-test");
  const auto vertex = [&](const char* id, double x, double y) {
    topology::VertexSpec spec;
    spec.id = id;
    spec.x = x;
    spec.y = y;
    builder.add_vertex(spec);
  };
  const auto edge = [&](const char* id, const char* from, const char* to, bool both,
                        double max_speed) {
    topology::EdgeSpec spec;
    spec.id = id;
    spec.from = from;
    spec.to = to;
    spec.bidirectional = both;
    spec.max_speed = max_speed;
    builder.add_edge(spec);
  };
  vertex("A", 0, 0);
  vertex("B", 5, 0);
  vertex("C", 10, 0);
  vertex("D", 10, 5);
  vertex("E", 13, 9);
  edge("ab", "A", "B", true, 2.0);
  edge("bc", "B", "C", true, 2.0);
  edge("cd", "C", "D", true, 2.0);
  edge("de", "D", "E", false, 2.0);
  auto built = std::move(builder).build();
  if (!built) throw std::runtime_error("test topology does not build");
  return std::make_shared<const topology::Topology>(std::move(built).value());
}

/// The union (as parts) of the named entities' footprints; empty ids are skipped.
inline MotionArea area_of(const topology::Topology& topology,
                          std::initializer_list<std::string> ids) {
  MotionArea area;
  for (const auto& id : ids) {
    if (!id.empty()) area.push_back(topology.footprint(*topology.find(id)));
  }
  return area;
}

/// A move from `from` over `edge` to `to`, allowed the three footprints.
inline MoveCommand move(const topology::Topology& topology, std::string id, const std::string& from,
                        const std::string& edge, const std::string& to, double max_speed,
                        std::optional<double> theta = std::nullopt) {
  const auto& target = topology.vertex(*topology.find(to));
  MoveCommand command;
  command.id = std::move(id);
  command.target_vertex = to;
  command.target = TargetPose{target.position.x(), target.position.y(), theta};
  command.edge = edge;
  command.max_speed = max_speed;
  command.area = area_of(topology, {from, edge, to});
  return command;
}

/// A vehicle standing at a vertex, facing +x, at time 0.
inline SimVehicle vehicle_at(std::shared_ptr<const topology::Topology> topology,
                             const std::string& vertex, SimVehicleConfig config = {}) {
  const auto& v = topology->vertex(*topology->find(vertex));
  auto created = SimVehicle::create(std::move(config), Pose{v.position.x(), v.position.y(), 0}, 0,
                                    std::move(topology));
  if (!created) throw std::runtime_error(created.error().message);
  return std::move(created).value();
}

inline CommandState state_of(const SimVehicle& vehicle, const CommandId& id) {
  const auto status = vehicle.status();
  const auto* command = status.find_command(id);
  if (command == nullptr) throw std::runtime_error("command not listed: " + id);
  return command->state;
}

/// Steps `vehicle` by `dt` until `done` holds (then returns true) or `limit` of simulated
/// time has passed (returns false). `each` runs after every step.
inline bool step_until(SimVehicle& vehicle, const std::function<bool()>& done, DurationNs dt,
                       DurationNs limit, const std::function<void()>& each = {}) {
  const TimeNs end = vehicle.now() + limit;
  while (!done()) {
    if (vehicle.now() >= end) return false;
    vehicle.step(dt);
    if (each) each();
  }
  return true;
}

/// Time from rest to rest over `length` with a trapezoid (or triangle) profile.
inline double trapezoid_time(double length, double speed, double acceleration, double deceleration) {
  const double ramp_distance = speed * speed / (2 * acceleration) + speed * speed / (2 * deceleration);
  if (length >= ramp_distance) {
    return length / speed + speed / (2 * acceleration) + speed / (2 * deceleration);
  }
  const double peak =
      std::sqrt(2 * acceleration * deceleration * length / (acceleration + deceleration));
  return peak / acceleration + peak / deceleration;
}

}  // namespace drover::ran::test
