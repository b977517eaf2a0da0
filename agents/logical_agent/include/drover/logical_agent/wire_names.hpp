#pragma once
// The names operators read and type for the logical agents' wire enums (idl/logical.idl):
// what droverctl prints and accepts.

#include <array>
#include <optional>
#include <string_view>

#include "logical.h"

namespace drover::logical_agent {

/// "idle", "driving", "operating", "parking", "charging", "waiting", "error", "paused".
inline std::string_view activity_name(msg::VehicleActivity activity) {
  static constexpr std::array<std::string_view, 8> kNames{"idle",     "driving", "operating", "parking",
                                                          "charging", "waiting", "error",     "paused"};
  const auto index = static_cast<std::size_t>(activity);
  return index < kNames.size() ? kNames[index] : "unknown";
}

/// "queued", "running", "finished", "failed", "withdrawn".
inline std::string_view order_state_name(msg::OrderState state) {
  static constexpr std::array<std::string_view, 5> kNames{"queued", "running", "finished", "failed", "withdrawn"};
  const auto index = static_cast<std::size_t>(state);
  return index < kNames.size() ? kNames[index] : "unknown";
}

inline constexpr std::array<std::string_view, 4> kSeverityNames{"info", "warning", "error", "critical"};

/// "info", "warning", "error", "critical".
inline std::string_view severity_name(msg::AlarmSeverity severity) {
  const auto index = static_cast<std::size_t>(severity);
  return index < kSeverityNames.size() ? kSeverityNames[index] : "unknown";
}

/// The severity named `name` (as severity_name gives it), nullopt for another name.
inline std::optional<msg::AlarmSeverity> severity_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kSeverityNames.size(); ++i) {
    if (kSeverityNames[i] == name) return static_cast<msg::AlarmSeverity>(i);
  }
  return std::nullopt;
}

}  // namespace drover::logical_agent
