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
  const struct {
    const char* name;
    double value;
    bool zero_allowed;
  } fields[] = {
      {"max_speed", vehicle.max_speed, false},   {"acceleration", vehicle.acceleration, false},
      {"deceleration", vehicle.deceleration, false}, {"length", vehicle.length, false},
      {"width", vehicle.width, false},           {"payload", vehicle.payload, true},
  };
  for (const auto& field : fields) {
    const bool in_range = field.zero_allowed ? field.value >= 0 : field.value > 0;
    if (!std::isfinite(field.value) || !in_range) {
      return fail(ErrorCode::invalid_argument,
                  fmt::format("vehicle '{}': {} must be {} and finite, got {}", vehicle.id,
                              field.name, field.zero_allowed ? ">= 0" : "> 0", field.value));
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
