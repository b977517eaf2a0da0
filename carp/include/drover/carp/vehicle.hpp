#pragma once
// The vehicle a route is planned for, and which entities it may use.

#include <optional>
#include <string>

#include "drover/common/result.hpp"
#include "drover/topology/model.hpp"

namespace drover::carp {

/// What the planner needs to know about a vehicle (or a person). SI units.
struct VehicleProfile {
  std::string id;            ///< the vehicle's id (for messages)
  std::string type;          ///< matched against allowed/forbidden vehicle types
  double max_speed = 1.0;    ///< m/s, 0.001 to 100
  double acceleration = 1.0; ///< m/s^2, 0.001 to 100 (carried for the vehicle; see docs/carp.md)
  double deceleration = 1.0; ///< m/s^2, 0.001 to 100
  double length = 1.0;       ///< m, 0.001 to 1000; sets the clearance time
  double width = 1.0;        ///< m, 0.001 to 1000
  double payload = 0.0;      ///< kg, 0 to 1e9; the load it carries on this route

  friend bool operator==(const VehicleProfile&, const VehicleProfile&) = default;
};

/// Checks that every number is finite and within its physical bounds (above).
/// \return ok, or invalid_argument naming the first bad field and its value.
Status validate(const VehicleProfile& vehicle);

/// Why `vehicle` may not use an entity with these restrictions (type not allowed, type
/// forbidden, payload, length or width over the limit); nullopt when it may.
/// Max speed is not a prohibition: it only slows the vehicle down.
std::optional<std::string> restriction_violation(const topology::Restrictions& restrictions,
                                                 const VehicleProfile& vehicle);

}  // namespace drover::carp
