#include "drover/ran_runner/wire.hpp"

#include <boost/geometry/algorithms/correct.hpp>
#include <boost/geometry/algorithms/is_valid.hpp>
#include <fmt/format.h>

namespace drover::ran {

namespace {

msg::RanPolygon polygon_to_wire(const topology::Polygon& polygon) {
  msg::RanPolygon wire;
  for (const auto& corner : polygon.outer()) {
    msg::Point2 point;
    point.x(corner.x());
    point.y(corner.y());
    wire.ring().push_back(point);
  }
  return wire;
}

/// Either winding and an open or closed ring are taken (ROS lists outlines counter-clockwise,
/// Boost.Geometry wants them clockwise and closed): corrected here, since an area computed
/// from the other winding is negative, and every footprint would seem to lie inside any
/// allocated area.
topology::Polygon polygon_from_wire(const msg::RanPolygon& wire) {
  topology::Polygon polygon;
  for (const auto& point : wire.ring()) polygon.outer().emplace_back(point.x(), point.y());
  boost::geometry::correct(polygon);
  return polygon;
}

msg::RanActionKind kind_to_wire(ActionKind kind) {
  switch (kind) {
    case ActionKind::load: return msg::RAN_ACTION_LOAD;
    case ActionKind::unload: return msg::RAN_ACTION_UNLOAD;
    case ActionKind::charge: return msg::RAN_ACTION_CHARGE;
    case ActionKind::custom: return msg::RAN_ACTION_CUSTOM;
  }
  return msg::RAN_ACTION_CUSTOM;
}

}  // namespace

msg::RanMove to_wire(const MoveCommand& command) {
  msg::RanMove move;
  move.id(command.id);
  move.target_vertex(command.target_vertex);
  move.x(command.target.x);
  move.y(command.target.y);
  move.theta().present(command.target.theta.has_value());
  move.theta().value(command.target.theta.value_or(0.0));
  move.edge(command.edge);
  move.max_speed(command.max_speed);
  for (const auto& part : command.area) move.area().push_back(polygon_to_wire(part));
  return move;
}

MoveCommand from_wire(const msg::RanMove& move) {
  MoveCommand command;
  command.id = move.id();
  command.target_vertex = move.target_vertex();
  command.target.x = move.x();
  command.target.y = move.y();
  if (move.theta().present()) command.target.theta = move.theta().value();
  command.edge = move.edge();
  command.max_speed = move.max_speed();
  for (const auto& part : move.area()) command.area.push_back(polygon_from_wire(part));
  return command;
}

msg::RanAction to_wire(const ActionCommand& command) {
  msg::RanAction action;
  action.id(command.id);
  action.kind(kind_to_wire(command.kind));
  action.name(command.name);
  for (const auto& [name, value] : command.parameters) {
    msg::Property property;
    property.name(name);
    property.value(value);
    action.parameters().push_back(property);
  }
  return action;
}

Result<ActionCommand> from_wire(const msg::RanAction& action) {
  ActionCommand command;
  command.id = action.id();
  switch (action.kind()) {
    case msg::RAN_ACTION_LOAD: command.kind = ActionKind::load; break;
    case msg::RAN_ACTION_UNLOAD: command.kind = ActionKind::unload; break;
    case msg::RAN_ACTION_CHARGE: command.kind = ActionKind::charge; break;
    case msg::RAN_ACTION_CUSTOM: command.kind = ActionKind::custom; break;
    default:
      return fail(ErrorCode::invalid_argument,
                  fmt::format("action '{}': unknown kind {}", action.id(),
                              static_cast<int>(action.kind())));
  }
  command.name = action.name();
  for (const auto& property : action.parameters()) {
    command.parameters[property.name()] = property.value();
  }
  return command;
}

msg::RanStatus to_wire(const VehicleStatus& status) {
  msg::RanStatus wire;
  wire.vehicle_id(status.vehicle_id);
  wire.sequence_number(status.sequence);
  wire.time().ns(status.time);
  wire.pose().x(status.pose.x);
  wire.pose().y(status.pose.y);
  wire.pose().theta(status.pose.theta);
  wire.linear_speed(status.linear_speed);
  wire.angular_speed(status.angular_speed);
  wire.state_of_charge(status.battery.state_of_charge);
  wire.energy_wh(status.battery.energy_wh);
  wire.charging(status.battery.charging);
  wire.load(to_string(status.load));
  wire.paused(status.paused);
  for (const auto& command : status.commands) {
    msg::RanCommandProgress progress;
    progress.id(command.id);
    progress.state(to_string(command.state));
    progress.code(command.code);
    progress.reason(command.reason);
    wire.commands().push_back(progress);
  }
  for (const auto& error : status.errors) {
    msg::RanError entry;
    entry.level(to_string(error.level));
    entry.code(error.code);
    entry.text(error.text);
    wire.errors().push_back(entry);
  }
  wire.footprint(polygon_to_wire(status.footprint));
  wire.actions(status.actions);
  return wire;
}

Result<VehicleStatus> from_wire(const msg::RanStatus& wire) {
  VehicleStatus status;
  status.vehicle_id = wire.vehicle_id();
  status.sequence = wire.sequence_number();
  status.time = wire.time().ns();
  status.pose = Pose{wire.pose().x(), wire.pose().y(), wire.pose().theta()};
  status.linear_speed = wire.linear_speed();
  status.angular_speed = wire.angular_speed();
  status.battery = BatteryStatus{wire.state_of_charge(), wire.energy_wh(), wire.charging()};
  const auto load = load_state_from_string(wire.load());
  if (!load) {
    return fail(ErrorCode::invalid_argument,
                fmt::format("status of '{}': unknown load state '{}'", wire.vehicle_id(), wire.load()));
  }
  status.load = *load;
  status.paused = wire.paused();
  for (const auto& progress : wire.commands()) {
    const auto state = command_state_from_string(progress.state());
    if (!state) {
      return fail(ErrorCode::invalid_argument,
                  fmt::format("status of '{}': command '{}' has unknown state '{}'",
                              wire.vehicle_id(), progress.id(), progress.state()));
    }
    status.commands.push_back({progress.id(), *state, progress.code(), progress.reason()});
  }
  for (const auto& error : wire.errors()) {
    const auto level = error_level_from_string(error.level());
    if (!level) {
      return fail(ErrorCode::invalid_argument,
                  fmt::format("status of '{}': error '{}' has unknown level '{}'",
                              wire.vehicle_id(), error.code(), error.level()));
    }
    status.errors.push_back({*level, error.code(), error.text()});
  }
  status.footprint = polygon_from_wire(wire.footprint());
  status.actions = wire.actions();
  // The logical agent checks the footprint against what it allocated and releases what it
  // no longer touches: an empty or self-crossing one would pass both checks unseen.
  if (std::string why; !boost::geometry::is_valid(status.footprint, why)) {
    return fail(ErrorCode::invalid_argument,
                fmt::format("status of '{}': the footprint is not a valid polygon ({})", wire.vehicle_id(), why));
  }
  return status;
}

}  // namespace drover::ran
