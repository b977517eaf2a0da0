#pragma once
// Independent checks of a planned route against the request, the topology and the other
// agents' reservations: what the Route contract (route.hpp) promises, recomputed here from
// the topology alone (not from the planner's own arrays).

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "drover/carp/planner.hpp"
#include "drover/topology/timeline.hpp"

namespace drover::carp::test {

inline TimeNs sec(double seconds) { return seconds_to_ns(seconds); }

/// The speed a vehicle drives an edge at, from the documented rule.
inline double edge_speed(const topology::Topology& t, topology::EntityIndex edge,
                         const VehicleProfile& vehicle) {
  const topology::Edge& e = t.edge(edge);
  double speed = std::min(vehicle.max_speed, e.max_speed);
  for (const auto* r : {&e.restrictions, &t.vertex(e.from).restrictions,
                        &t.vertex(e.to).restrictions}) {
    if (r->max_speed) speed = std::min(speed, *r->max_speed);
  }
  return speed;
}
inline DurationNs edge_travel(const topology::Topology& t, topology::EntityIndex edge,
                              const VehicleProfile& vehicle) {
  return std::llround(t.edge(edge).length / edge_speed(t, edge, vehicle) * 1e9);
}
inline DurationNs edge_clearance(const topology::Topology& t, topology::EntityIndex edge,
                                 const VehicleProfile& vehicle) {
  return static_cast<DurationNs>(std::ceil(vehicle.length / edge_speed(t, edge, vehicle) * 1e9));
}

/// Everything a route must satisfy. Reports failures through gtest; returns true when
/// none was found.
inline bool check_route(const topology::Topology& t, const topology::TimelineSet& timelines,
                        const PlanRequest& request, const Route& route) {
  const auto failures_before = ::testing::UnitTest::GetInstance()->current_test_info()
                                   ->result()->total_part_count();
  const auto& steps = route.steps;
  EXPECT_FALSE(steps.empty());
  if (steps.empty()) return false;
  EXPECT_EQ(steps.front().entity, request.start);
  EXPECT_EQ(steps.front().window.start, request.start_time);
  EXPECT_EQ(steps.size() % 2, 1u) << "a route alternates vertex, edge, ..., vertex";
  double distance = 0;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const topology::RouteStep& step = steps[i];
    EXPECT_TRUE(step.window.valid()) << "step " << i;
    EXPECT_EQ(t.is_vertex(step.entity), i % 2 == 0) << "step " << i;
    if (i % 2 == 1 && i + 1 < steps.size()) {
      const topology::Edge& e = t.edge(step.entity);
      const auto from = steps[i - 1].entity;
      const auto to = steps[i + 1].entity;
      EXPECT_TRUE((e.from == from && e.to == to) || (e.bidirectional && e.from == to && e.to == from))
          << "step " << i << ": edge " << e.id << " does not lead from " << t.id(from) << " to "
          << t.id(to) << " in an allowed direction";
      distance += e.length;
      const DurationNs clearance = edge_clearance(t, step.entity, request.vehicle);
      EXPECT_EQ(steps[i - 1].window.end, step.window.start + clearance) << "step " << i - 1;
      EXPECT_EQ(step.window.end, steps[i + 1].window.start + clearance) << "step " << i;
      EXPECT_GE(steps[i + 1].window.start - step.window.start,
                edge_travel(t, step.entity, request.vehicle))
          << "edge step " << i << " is driven faster than allowed";
    }
    if (i > 0) {
      EXPECT_GE(step.window.start, steps[i - 1].window.start) << "step " << i;
    }
  }
  EXPECT_DOUBLE_EQ(route.distance, distance);

  // Stops: visited in order, each held for its dwell, the last one as asked.
  EXPECT_EQ(route.stop_steps.size(), request.stops.size());
  EXPECT_EQ(route.stop_arrivals.size(), request.stops.size());
  if (route.stop_steps.size() == request.stops.size() &&
      route.stop_arrivals.size() == request.stops.size()) {
    for (std::size_t k = 0; k < request.stops.size(); ++k) {
      const std::size_t at = route.stop_steps[k];
      EXPECT_LT(at, steps.size());
      if (at >= steps.size()) return false;
      EXPECT_EQ(steps[at].entity, request.stops[k].vertex) << "stop " << k;
      EXPECT_GE(route.stop_arrivals[k], steps[at].window.start) << "stop " << k;
      if (k > 0) {
        EXPECT_GE(at, route.stop_steps[k - 1]);
        EXPECT_GE(route.stop_arrivals[k], route.stop_arrivals[k - 1]);
      }
      const bool last = k + 1 == request.stops.size();
      const DurationNs dwell = request.stops[k].dwell.value_or(0);
      if (!last) {
        // The vehicle leaves the stop (or makes the next stop there) after the dwell.
        const TimeNs leaves = route.stop_steps[k + 1] == at ? route.stop_arrivals[k + 1]
                                                            : steps[at + 1].window.start;
        EXPECT_GE(leaves - route.stop_arrivals[k], dwell) << "stop " << k << " too short";
      }
    }
    EXPECT_EQ(route.stop_steps.back(), steps.size() - 1);
    EXPECT_EQ(route.arrival, route.stop_arrivals.back());
  }
  const auto& last = request.stops.back();
  EXPECT_EQ(steps.back().entity, last.vertex);
  EXPECT_EQ(steps.back().window.end, last.dwell ? route.arrival + *last.dwell : kForever);
  EXPECT_EQ(route.travel_time, route.arrival - request.start_time);

  // Never overlaps another agent's reservation on the step's entity or its conflict set
  // (I1, from the other agents' real reservations), nor a lock there.
  for (std::size_t i = 0; i < steps.size(); ++i) {
    std::vector<topology::EntityIndex> places{steps[i].entity};
    for (auto f : t.conflicts(steps[i].entity)) places.push_back(f);
    for (auto place : places) {
      const auto& timeline = timelines.timeline(place);
      for (const auto& r : timeline.reservations) {
        if (r.agent == request.agent || r.shadow()) continue;
        EXPECT_FALSE(r.window.overlaps(steps[i].window))
            << "step " << i << " on " << t.id(steps[i].entity) << " overlaps agent " << r.agent
            << "'s reservation of " << t.id(place);
      }
      for (const auto& lock : timeline.locks) {
        EXPECT_FALSE(lock.window.overlaps(steps[i].window))
            << "step " << i << " on " << t.id(steps[i].entity) << " overlaps lock " << lock.id
            << " on " << t.id(place);
      }
    }
  }
  return ::testing::UnitTest::GetInstance()->current_test_info()->result()->total_part_count() ==
         failures_before;
}

/// A topology with its timelines and a planner, as a routing agent holds them.
struct World {
  explicit World(topology::Topology built, PlannerOptions options = {})
      : topology(std::move(built)),
        graph(std::make_shared<RoutingGraph>(topology)),
        timelines(topology.conflict_sets()),
        planner(graph, options) {}
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  topology::EntityIndex at(const std::string& id) const {
    const auto found = topology.find(id);
    EXPECT_TRUE(found.has_value()) << "no entity " << id;
    return found.value_or(topology::kNoEntity);
  }
  /// Reserves one step for another agent (a test fixture, not a route).
  void occupy(const std::string& agent, const std::string& entity, TimeNs from, TimeNs until) {
    const auto done = timelines.reserve(agent, next_route++, {{at(entity), {from, until}}});
    ASSERT_TRUE(done.has_value()) << done.error().message;
  }

  topology::Topology topology;
  std::shared_ptr<RoutingGraph> graph;
  topology::TimelineSet timelines;
  Planner planner;
  topology::RouteId next_route = 1000;
};

inline VehicleProfile unit_vehicle(std::string id = "v1") {
  VehicleProfile v;
  v.id = std::move(id);
  v.type = "agv";
  return v;  // 1 m/s, 1 m long: clearance 1 s on a 1 m/s edge
}

inline PlanRequest request_to(const World& world, const std::string& agent,
                              const std::string& start, std::vector<Stop> stops,
                              TimeNs start_time = 0) {
  PlanRequest r;
  r.agent = agent;
  r.vehicle = unit_vehicle();
  r.start = world.at(start);
  r.start_time = start_time;
  r.stops = std::move(stops);
  return r;
}

}  // namespace drover::carp::test
