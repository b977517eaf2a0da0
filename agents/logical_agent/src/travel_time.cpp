#include "agents/logical_agent/src/travel_time.hpp"

#include <algorithm>
#include <cmath>

namespace drover::logical_agent {

DurationNs drive_time(double distance, double speed, const carp::VehicleProfile& vehicle) {
  if (!(distance > 0)) return 0;
  const double a = vehicle.acceleration;
  const double d = vehicle.deceleration;
  const double v_max = vehicle.max_speed;
  const double v0 = std::clamp(speed, 0.0, v_max);
  const double braking = v0 * v0 / (2 * d);
  if (distance <= braking) {
    // Braking all the way: the mean speed is v0 / 2 (at most; a later start braking is faster).
    return seconds_to_ns(2 * distance / std::max(v0, 1e-9));
  }
  // Peak speed of an accelerate-then-brake profile that covers exactly `distance`.
  const double peak = std::sqrt((distance + v0 * v0 / (2 * a)) / (1 / (2 * a) + 1 / (2 * d)));
  if (peak <= v_max) return seconds_to_ns((peak - v0) / a + peak / d);
  const double ramps = (v_max * v_max - v0 * v0) / (2 * a) + v_max * v_max / (2 * d);
  return seconds_to_ns((v_max - v0) / a + v_max / d + (distance - ramps) / v_max);
}

}  // namespace drover::logical_agent
