#include "agents/topology_agent/wire.hpp"

#include <boost/geometry.hpp>

namespace drover::topology_agent {

namespace {

msg::OptionalDouble to_wire(const std::optional<double>& value) {
  msg::OptionalDouble out;
  out.present(value.has_value());
  out.value(value.value_or(0.0));
  return out;
}

msg::Point2 to_wire(const topology::Point& point) {
  msg::Point2 out;
  out.x(point.x());
  out.y(point.y());
  return out;
}

msg::Restrictions to_wire(const topology::Restrictions& restrictions) {
  msg::Restrictions out;
  out.max_speed(to_wire(restrictions.max_speed));
  out.max_payload(to_wire(restrictions.max_payload));
  out.allowed_vehicle_types(restrictions.allowed_vehicle_types);
  out.forbidden_vehicle_types(restrictions.forbidden_vehicle_types);
  out.max_vehicle_length(to_wire(restrictions.max_vehicle_length));
  out.max_vehicle_width(to_wire(restrictions.max_vehicle_width));
  return out;
}

Result<topology::EntityIndex> find_entity(const topology::Topology& topology, const std::string& id,
                                          const char* what) {
  auto entity = topology.find(id);
  if (!entity) {
    return fail(ErrorCode::not_found, std::string(what) + ": unknown entity '" + id +
                                          "' in topology '" + topology.name() + "'");
  }
  return *entity;
}

}  // namespace

msg::EntityDescription to_wire_description(const topology::Topology& topology,
                                           topology::EntityIndex entity) {
  msg::EntityDescription out;
  out.id(topology.id(entity));
  out.topology(topology.name());
  out.partition(topology.partition(entity));
  if (topology.is_vertex(entity)) {
    const auto& vertex = topology.vertex(entity);
    out.kind(msg::ENTITY_VERTEX);
    out.vertex_kind(topology::to_string(vertex.kind));
    out.position(to_wire(vertex.position));
    out.orientation(to_wire(vertex.orientation));
    for (const auto& move : topology.moves_from(entity)) out.out_edges().push_back(topology.id(move.edge));
  } else {
    const auto& edge = topology.edge(entity);
    out.kind(msg::ENTITY_EDGE);
    out.from(topology.id(edge.from));
    out.to(topology.id(edge.to));
    out.bidirectional(edge.bidirectional);
    out.length(edge.length);
    out.max_speed(edge.max_speed);
  }
  for (const auto& point : topology.footprint(entity).outer()) out.footprint().push_back(to_wire(point));
  out.restrictions(to_wire(topology.restrictions(entity)));
  const auto& properties =
      topology.is_vertex(entity) ? topology.vertex(entity).properties : topology.edge(entity).properties;
  for (const auto& [name, value] : properties) {
    msg::Property property;
    property.name(name);
    property.value(value);
    out.properties().push_back(std::move(property));
  }
  for (auto other : topology.conflicts(entity)) out.conflicts().push_back(topology.id(other));
  return out;
}

msg::Interval to_wire(const topology::Interval& interval) {
  msg::Interval out;
  out.start(interval.start);
  out.end(interval.end);
  return out;
}

topology::Interval from_wire(const msg::Interval& interval) {
  return topology::Interval{interval.start(), interval.end()};
}

msg::Reservation to_wire(const topology::Topology& topology, const topology::Reservation& item) {
  msg::Reservation out;
  out.agent(item.agent);
  out.route(item.route);
  out.step(item.step);
  out.entity(topology.id(item.entity));
  out.origin(topology.id(item.origin));
  out.window(to_wire(item.window));
  out.prepared(item.prepared);
  return out;
}

Result<topology::Reservation> from_wire(const topology::Topology& topology,
                                        const msg::Reservation& item) {
  auto entity = find_entity(topology, item.entity(), "reservation entity");
  if (!entity) return unexpected(entity.error());
  auto origin = find_entity(topology, item.origin(), "reservation origin");
  if (!origin) return unexpected(origin.error());
  topology::Reservation out;
  out.agent = item.agent();
  out.route = item.route();
  out.step = item.step();
  out.entity = *entity;
  out.origin = *origin;
  out.window = from_wire(item.window());
  out.prepared = false;  // set by the timeline set, never by a requester
  return out;
}

std::string wire_lock_id(const std::string& agent_id, topology::LockId id) {
  return agent_id + "/" + std::to_string(id);
}

msg::TimelineState to_wire_timeline(const topology::Topology& topology, const std::string& agent_id,
                                    topology::EntityIndex entity, const topology::Timeline& timeline) {
  msg::TimelineState out;
  out.entity(topology.id(entity));
  out.version(timeline.version);
  for (const auto& item : timeline.reservations) out.reservations().push_back(to_wire(topology, item));
  for (const auto& lock : timeline.locks) {
    msg::Lock wire_lock;
    wire_lock.id(wire_lock_id(agent_id, lock.id));
    wire_lock.window(to_wire(lock.window));
    wire_lock.operator_id(lock.operator_id);
    wire_lock.reason(lock.reason);
    out.locks().push_back(std::move(wire_lock));
  }
  out.holder(timeline.holder.value_or(std::string{}));
  out.waiting(timeline.waiting);
  return out;
}

}  // namespace drover::topology_agent
