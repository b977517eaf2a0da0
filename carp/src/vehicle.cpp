#include "drover/carp/vehicle.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace drover::carp {

namespace {

bool listed(const std::vector<std::string>& types, const std::string& type) {
  return std::find(types.begin(), types.end(), type) != types.end();
}

}  // namespace

Status validate(const VehicleProfile& vehicle) {
  // Physical bounds, not only signs: a vehicle that accelerates at 1e-19 m/s^2 needs
  // longer than the clock can count to reach any speed, and its times would overflow.
  const struct {
    const char* name;
    double value;
    double low;
    double high;
    const char* unit;
  } fields[] = {
      {"max_speed", vehicle.max_speed, 0.001, 100.0, "m/s"},
      {"acceleration", vehicle.acceleration, 0.001, 100.0, "m/s^2"},
      {"deceleration", vehicle.deceleration, 0.001, 100.0, "m/s^2"},
      {"length", vehicle.length, 0.001, 1000.0, "m"},
      {"width", vehicle.width, 0.001, 1000.0, "m"},
      {"payload", vehicle.payload, 0.0, 1e9, "kg"},
  };
  for (const auto& field : fields) {
    if (!std::isfinite(field.value) || field.value < field.low || field.value > field.high) {
      const std::string whose = vehicle.id.empty() ? std::string() : fmt::format("vehicle '{}': ", vehicle.id);
      return fail(ErrorCode::invalid_argument, fmt::format("{}{} must be from {} to {} {}, got {}", whose, field.name,
                                                           field.low, field.high, field.unit, field.value));
    }
  }
  return {};
}

std::optional<std::string> restriction_violation(const topology::Restrictions& restrictions,
                                                 const VehicleProfile& vehicle) {
  if (!restrictions.allowed_vehicle_types.empty() &&
      !listed(restrictions.allowed_vehicle_types, vehicle.type)) {
    return fmt::format("vehicle type '{}' is not among the allowed types", vehicle.type);
  }
  if (listed(restrictions.forbidden_vehicle_types, vehicle.type)) {
    return fmt::format("vehicle type '{}' is forbidden", vehicle.type);
  }
  if (restrictions.max_payload && vehicle.payload > *restrictions.max_payload) {
    return fmt::format("payload {} kg exceeds the limit of {} kg", vehicle.payload,
                       *restrictions.max_payload);
  }
  if (restrictions.max_vehicle_length && vehicle.length > *restrictions.max_vehicle_length) {
    return fmt::format("vehicle length {} m exceeds the limit of {} m", vehicle.length,
                       *restrictions.max_vehicle_length);
  }
  if (restrictions.max_vehicle_width && vehicle.width > *restrictions.max_vehicle_width) {
    return fmt::format("vehicle width {} m exceeds the limit of {} m", vehicle.width,
                       *restrictions.max_vehicle_width);
  }
  return std::nullopt;
}

}  // namespace drover::carp
