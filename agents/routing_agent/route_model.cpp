#include "agents/routing_agent/route_model.hpp"

#include <algorithm>

#include "drover/topology/topology_builder.hpp"

namespace drover::routing_agent {

namespace {

std::optional<double> from_wire(const msg::OptionalDouble& value) {
  return value.present() ? std::optional<double>(value.value()) : std::nullopt;
}

topology::Restrictions from_wire(const msg::Restrictions& wire) {
  topology::Restrictions out;
  out.max_speed = from_wire(wire.max_speed());
  out.max_payload = from_wire(wire.max_payload());
  out.allowed_vehicle_types = wire.allowed_vehicle_types();
  out.forbidden_vehicle_types = wire.forbidden_vehicle_types();
  out.max_vehicle_length = from_wire(wire.max_vehicle_length());
  out.max_vehicle_width = from_wire(wire.max_vehicle_width());
  return out;
}

topology::Polygon footprint(const msg::EntityDescription& description) {
  topology::Polygon polygon;
  for (const auto& point : description.footprint()) {
    polygon.outer().push_back(topology::Point(point.x(), point.y()));
  }
  return polygon;
}

topology::Properties properties(const msg::EntityDescription& description) {
  topology::Properties out;
  for (const auto& property : description.properties()) out[property.name()] = property.value();
  return out;
}

}  // namespace

Result<std::unique_ptr<RouteModel>> RouteModel::build(const KnownEntities& known,
                                                      carp::PlannerOptions options) {
  std::string name;
  for (const auto& [id, description] : known.all()) {
    if (name.empty()) name = description.topology();
  }
  topology::TopologyBuilder builder(name);
  for (const auto& [id, description] : known.all()) {
    if (description.kind() != msg::ENTITY_VERTEX) continue;
    topology::VertexSpec vertex;
    vertex.id = id;
    vertex.x = description.position().x();
    vertex.y = description.position().y();
    vertex.orientation = from_wire(description.orientation());
    vertex.kind = topology::vertex_kind_from_string(description.vertex_kind()).value_or(topology::VertexKind::waypoint);
    vertex.footprint = footprint(description);
    vertex.restrictions = from_wire(description.restrictions());
    vertex.properties = properties(description);
    vertex.partition = description.partition();
    vertex.where = "entity '" + id + "'";
    builder.add_vertex(std::move(vertex));
  }
  for (const auto& [id, description] : known.all()) {
    if (description.kind() != msg::ENTITY_EDGE) continue;
    const auto* from = known.find(description.from());
    const auto* to = known.find(description.to());
    if (from == nullptr || to == nullptr || from->kind() != msg::ENTITY_VERTEX ||
        to->kind() != msg::ENTITY_VERTEX) {
      continue;
    }
    topology::EdgeSpec edge;
    edge.id = id;
    edge.from = description.from();
    edge.to = description.to();
    edge.bidirectional = description.bidirectional();
    edge.length = description.length();
    edge.max_speed = description.max_speed();
    edge.footprint = footprint(description);
    edge.restrictions = from_wire(description.restrictions());
    edge.properties = properties(description);
    edge.partition = description.partition();
    edge.where = "entity '" + id + "'";
    builder.add_edge(std::move(edge));
  }
  auto built = std::move(builder).build();
  if (!built) {
    const auto& first = built.error().front();
    return fail(ErrorCode::internal, "cannot build the topology from the descriptions the topology agents "
                                     "published: " + first.where + ": " + first.what);
  }
  auto topology = std::make_shared<const topology::Topology>(std::move(*built));
  std::vector<std::vector<topology::EntityIndex>> conflict_sets(topology->entity_count());
  for (topology::EntityIndex entity = 0; entity < topology->entity_count(); ++entity) {
    for (const auto& other : known.find(topology->id(entity))->conflicts()) {
      // Unknown members only occur outside the components KnownEntities::first_missing
      // found complete, which no plan on this model reaches.
      if (auto index = topology->find(other)) conflict_sets[entity].push_back(*index);
    }
    std::sort(conflict_sets[entity].begin(), conflict_sets[entity].end());
  }
  auto graph = std::make_shared<const carp::RoutingGraph>(*topology);
  return std::unique_ptr<RouteModel>(
      new RouteModel(std::move(topology), std::move(graph), std::move(conflict_sets), options));
}

RouteModel::RouteModel(std::shared_ptr<const topology::Topology> topology,
                       std::shared_ptr<const carp::RoutingGraph> graph,
                       std::vector<std::vector<topology::EntityIndex>> conflict_sets,
                       carp::PlannerOptions options)
    : topology_(std::move(topology)),
      graph_(std::move(graph)),
      planner_(graph_, options),
      timelines_(std::move(conflict_sets)),
      planning_(timelines_) {}

const topology::TimelineSet& RouteModel::planning_timelines() {
  if (planning_stale_) {
    planning_ = timelines_;
    planning_.widen_to_step_hulls();
    planning_stale_ = false;
  }
  return planning_;
}

bool RouteModel::apply(const msg::TimelineState& state) {
  const auto entity = topology_->find(state.entity());
  if (!entity) return false;
  topology::Timeline timeline;
  timeline.version = state.version();
  timeline.reservations.reserve(state.reservations().size());
  for (const auto& wire : state.reservations()) {
    topology::Reservation item;
    item.agent = wire.agent();
    item.route = wire.route();
    item.step = wire.step();
    item.entity = *entity;
    item.origin = topology_->find(wire.origin()).value_or(topology::kNoEntity);
    item.window = topology::Interval{wire.window().start(), wire.window().end()};
    item.prepared = wire.prepared();
    timeline.reservations.push_back(std::move(item));
  }
  for (const auto& wire : state.locks()) {
    topology::Lock lock;
    lock.entity = *entity;
    lock.window = topology::Interval{wire.window().start(), wire.window().end()};
    lock.operator_id = wire.operator_id();
    lock.reason = wire.reason();
    timeline.locks.push_back(std::move(lock));
  }
  if (!state.holder().empty()) timeline.holder = state.holder();
  timeline.waiting = state.waiting();
  planning_stale_ = true;
  return static_cast<bool>(timelines_.replace_timeline(*entity, std::move(timeline)));
}

}  // namespace drover::routing_agent
