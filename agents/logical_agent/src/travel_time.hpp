#pragma once
// How long a vehicle needs for a distance, from its speed profile (no DDS). Used to
// estimate when the vehicle reaches its next window, so that a delay is propagated by what
// it will really need rather than by a constant.

#include "drover/carp/vehicle.hpp"
#include "drover/common/clock.hpp"

namespace drover::logical_agent {

/// Time to drive `distance` metres starting at `speed` m/s and ending at rest, with a
/// trapezoidal profile: accelerate at vehicle.acceleration up to vehicle.max_speed, brake
/// at vehicle.deceleration. A speed above max_speed is taken as max_speed; a distance too
/// short to brake in is covered while braking. \pre the profile is valid (carp::validate).
/// \return >= 0; 0 for distance <= 0.
DurationNs drive_time(double distance, double speed, const carp::VehicleProfile& vehicle);

}  // namespace drover::logical_agent
