#pragma once
// Vehicle profiles as JSON files: an object with any of id, type (strings) and max_speed,
// acceleration, deceleration, length, width, payload (numbers, SI units); fields left out
// keep carp::VehicleProfile's defaults. Example: {"id": "V1", "max_speed": 1.0,
// "acceleration": 0.5, "deceleration": 0.5, "length": 0.6, "width": 0.4}.

#include <string>

#include <nlohmann/json_fwd.hpp>

#include "drover/carp/vehicle.hpp"
#include "drover/common/result.hpp"

namespace drover::carp {

/// Reads a profile from parsed JSON. \return the validated profile, or parse (not an
///         object, a field of the wrong type, an unknown field) or invalid_argument (a value
///         out of range), each naming the field ("acceleration: ...").
Result<VehicleProfile> vehicle_profile_from_json(const nlohmann::json& json);

/// Parses a profile from JSON text; `where` names the source in messages (a file name).
/// \return the validated profile, or parse (not JSON, a NUL byte, a key given twice, not an
///         object, a field of the wrong type, an unknown field) or invalid_argument (a value
///         out of range), each naming `where` and the field or the line and column
///         ("v.json:max_speed: key given twice in the same object"; several such problems
///         joined by "; ").
Result<VehicleProfile> parse_vehicle_profile(const std::string& text, const std::string& where);

/// Reads and parses the file at `path`. \return as parse_vehicle_profile, or io when the
///         file cannot be read.
Result<VehicleProfile> read_vehicle_profile(const std::string& path);

}  // namespace drover::carp
