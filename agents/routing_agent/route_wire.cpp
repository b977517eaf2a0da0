#include "agents/routing_agent/route_wire.hpp"

namespace drover::routing_agent {

carp::VehicleProfile from_wire(const msg::VehicleProfileMsg& vehicle) {
  carp::VehicleProfile out;
  out.id = vehicle.id();
  out.type = vehicle.type();
  out.max_speed = vehicle.max_speed();
  out.acceleration = vehicle.acceleration();
  out.deceleration = vehicle.deceleration();
  out.length = vehicle.length();
  out.width = vehicle.width();
  out.payload = vehicle.payload();
  return out;
}

msg::VehicleProfileMsg to_wire(const carp::VehicleProfile& vehicle) {
  msg::VehicleProfileMsg out;
  out.id(vehicle.id);
  out.type(vehicle.type);
  out.max_speed(vehicle.max_speed);
  out.acceleration(vehicle.acceleration);
  out.deceleration(vehicle.deceleration);
  out.length(vehicle.length);
  out.width(vehicle.width);
  out.payload(vehicle.payload);
  return out;
}

namespace {

Result<topology::EntityIndex> vertex(const topology::Topology& topology, const std::string& id,
                                     const std::string& field) {
  auto entity = topology.find(id);
  if (!entity) return fail(ErrorCode::not_found, field + ": unknown vertex '" + id + "'");
  if (!topology.is_vertex(*entity)) {
    return fail(ErrorCode::invalid_argument, field + ": '" + id + "' is an edge, not a vertex");
  }
  return *entity;
}

}  // namespace

Result<carp::PlanRequest> to_plan_request(const topology::Topology& topology, const msg::RouteRequest& request,
                                          TimeNs now) {
  if (request.stops().empty()) return fail(ErrorCode::invalid_argument, "stops: a route needs at least one stop");
  carp::PlanRequest out;
  out.agent = request.agent();
  out.vehicle = from_wire(request.vehicle());
  auto start = vertex(topology, request.start(), "start");
  if (!start) return unexpected(start.error());
  out.start = *start;
  out.start_time = request.start_time() > 0 ? request.start_time() : now;
  for (std::size_t i = 0; i < request.stops().size(); ++i) {
    const auto& wire = request.stops()[i];
    const std::string field = "stops[" + std::to_string(i) + "]";
    auto stop = vertex(topology, wire.vertex(), field + ".vertex");
    if (!stop) return unexpected(stop.error());
    if (wire.has_dwell() && wire.dwell() < 0) {
      return fail(ErrorCode::invalid_argument, field + ".dwell: " + std::to_string(wire.dwell()) + " ns is negative");
    }
    out.stops.push_back(carp::Stop{*stop, wire.has_dwell() ? std::optional<DurationNs>(wire.dwell()) : std::nullopt});
  }
  return out;
}

void fill_route(const topology::Topology& topology, const carp::Route& route, msg::RouteReply& reply) {
  reply.steps().clear();
  for (const auto& step : route.steps) {
    msg::RouteStepMsg wire;
    wire.entity(topology.id(step.entity));
    wire.window().start(step.window.start);
    wire.window().end(step.window.end);
    reply.steps().push_back(std::move(wire));
  }
  reply.stop_steps().clear();
  for (auto index : route.stop_steps) reply.stop_steps().push_back(static_cast<std::uint32_t>(index));
  reply.stop_arrivals(route.stop_arrivals);
  reply.distance(route.distance);
  reply.arrival(route.arrival);
  reply.travel_time(route.travel_time);
}

}  // namespace drover::routing_agent
