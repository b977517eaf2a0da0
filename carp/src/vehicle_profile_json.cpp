#include "drover/carp/vehicle_profile_json.hpp"

#include <nlohmann/json.hpp>

#include "drover/common/json_document.hpp"
#include "drover/common/text_file.hpp"
#include "drover/topology/topology_builder.hpp"

namespace drover::carp {

Result<VehicleProfile> vehicle_profile_from_json(const nlohmann::json& json) {
  if (!json.is_object()) return fail(ErrorCode::parse, "a vehicle profile is a JSON object");
  VehicleProfile vehicle;
  for (const auto& [key, value] : json.items()) {
    std::string* text_field = key == "id" ? &vehicle.id : key == "type" ? &vehicle.type : nullptr;
    double* number = key == "max_speed"      ? &vehicle.max_speed
                     : key == "acceleration" ? &vehicle.acceleration
                     : key == "deceleration" ? &vehicle.deceleration
                     : key == "length"       ? &vehicle.length
                     : key == "width"        ? &vehicle.width
                     : key == "payload"      ? &vehicle.payload
                                             : nullptr;
    if (text_field != nullptr) {
      if (!value.is_string()) return fail(ErrorCode::parse, key + ": must be a string");
      *text_field = value.get<std::string>();
    } else if (number != nullptr) {
      if (!value.is_number()) return fail(ErrorCode::parse, key + ": must be a number");
      *number = value.get<double>();
    } else {
      return fail(ErrorCode::parse, key +
                                        ": unknown field (known: id, type, max_speed, acceleration, "
                                        "deceleration, length, width, payload)");
    }
  }
  if (auto valid = validate(vehicle); !valid) return unexpected(valid.error());
  return vehicle;
}

Result<VehicleProfile> parse_vehicle_profile(const std::string& text, const std::string& where) {
  const auto json = parse_json_document<nlohmann::json>(text);
  if (!json) {
    // One message (an Error has one): every problem as tools print one, on one line.
    std::string message;
    for (const auto& problem : json.error()) {
      if (!message.empty()) message += "; ";
      message += topology::diagnostic_text(where, topology::Diagnostic{problem.where, problem.what});
    }
    return fail(ErrorCode::parse, message);
  }
  auto vehicle = vehicle_profile_from_json(*json);
  if (!vehicle) return fail(vehicle.error().code, where + ": " + vehicle.error().message);
  return vehicle;
}

Result<VehicleProfile> read_vehicle_profile(const std::string& path) {
  auto text = read_text_file(path);
  if (!text) return fail(ErrorCode::io, path + ": " + text.error().message);
  return parse_vehicle_profile(*text, path);
}

}  // namespace drover::carp
