#include <cmath>

#include <boost/geometry.hpp>
#include <fmt/format.h>

#include "drover/ran/sim_vehicle.hpp"

namespace drover::ran {

namespace {

bool positive(double value) { return std::isfinite(value) && value > 0; }

Status require(bool ok, const char* field, double value, const char* expectation) {
  if (ok) return {};
  return fail(ErrorCode::invalid_argument,
              fmt::format("vehicle config: {} = {} must be {}", field, value, expectation));
}

}  // namespace

topology::Polygon SimVehicleConfig::default_footprint() {
  topology::Polygon rectangle;
  // Clockwise and closed, Boost.Geometry's default polygon.
  rectangle.outer() = {{-0.3, -0.2}, {-0.3, 0.2}, {0.3, 0.2}, {0.3, -0.2}, {-0.3, -0.2}};
  return rectangle;
}

Status SimVehicleConfig::validate() const {
  if (vehicle_id.empty()) return fail(ErrorCode::invalid_argument, "vehicle config: vehicle_id is empty");
  const std::pair<const char*, double> positives[] = {
      {"max_speed", max_speed},
      {"acceleration", acceleration},
      {"deceleration", deceleration},
      {"angular_speed", angular_speed},
      {"battery_capacity_wh", battery_capacity_wh},
      {"charge_wh_per_second", charge_wh_per_second},
  };
  for (const auto& [field, value] : positives) {
    if (auto ok = require(positive(value), field, value, "positive and finite"); !ok) return ok;
  }
  if (auto ok = require(std::isfinite(drain_wh_per_metre) && drain_wh_per_metre >= 0,
                        "drain_wh_per_metre", drain_wh_per_metre, ">= 0 and finite");
      !ok) {
    return ok;
  }
  if (auto ok = require(std::isfinite(battery_initial_wh) && battery_initial_wh >= 0 &&
                            battery_initial_wh <= battery_capacity_wh,
                        "battery_initial_wh", battery_initial_wh,
                        "within [0, battery_capacity_wh]");
      !ok) {
    return ok;
  }
  if (auto ok = require(std::isfinite(area_tolerance_m2) && area_tolerance_m2 >= 0,
                        "area_tolerance_m2", area_tolerance_m2, ">= 0 and finite");
      !ok) {
    return ok;
  }
  if (auto ok = require(std::isfinite(position_tolerance) && position_tolerance >= 0,
                        "position_tolerance", position_tolerance, ">= 0 and finite");
      !ok) {
    return ok;
  }
  if (load_duration < 0 || unload_duration < 0) {
    return fail(ErrorCode::invalid_argument, "vehicle config: action durations must be >= 0");
  }
  for (const auto& [name, duration] : custom_actions) {
    if (name.empty() || duration < 0) {
      return fail(ErrorCode::invalid_argument,
                  fmt::format("vehicle config: custom action '{}' needs a name and a duration >= 0",
                              name));
    }
  }
  if (recent_commands == 0) {
    return fail(ErrorCode::invalid_argument, "vehicle config: recent_commands must be >= 1");
  }
  topology::Polygon outline = footprint;
  boost::geometry::correct(outline);
  std::string reason;
  if (!boost::geometry::is_valid(outline, reason) || boost::geometry::area(outline) <= 0) {
    return fail(ErrorCode::invalid_argument,
                fmt::format("vehicle config: footprint is not a valid polygon ({})",
                            reason.empty() ? "zero area" : reason));
  }
  return {};
}

}  // namespace drover::ran
