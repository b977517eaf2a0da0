#pragma once
// Where RANs meet their commanders on DDS (docs/ran-sdk.md, "On the wire").

#include <string>

namespace drover::ran {

/// State topic of every vehicle's status, keyed on the vehicle id.
inline constexpr const char* kStatusTopic = "drover/ran/status";
/// Services drover/ran/command and drover/ran/sim_fault.
inline constexpr const char* kServiceArea = "ran";
inline constexpr const char* kCommandService = "command";
inline constexpr const char* kSimFaultService = "sim_fault";

/// The agent id of the RAN of a vehicle, by convention: "ran-<vehicle id>".
std::string ran_agent_id(const std::string& vehicle_id);

}  // namespace drover::ran
