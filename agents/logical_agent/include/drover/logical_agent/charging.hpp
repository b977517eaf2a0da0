#pragma once
// The logical agent's charging thresholds, shared by the agent, its command line and launch
// files, so that all three take the same defaults and refuse the same pairs.

#include <optional>
#include <string>

#include <fmt/format.h>

namespace drover::logical_agent {

/// Under this state of charge the vehicle charges before new work (0: never).
inline constexpr double kDefaultChargeBelow = 0.2;
/// The state of charge a charge aims at.
inline constexpr double kDefaultChargeTo = 0.9;

/// Why the pair cannot work, if it cannot: a charge that ends at or under the threshold that
/// starts one would be followed by another at once, for ever, and no order would run.
/// Each value on its own is the caller's to check (below in [0, 1], to in (0, 1]).
inline std::optional<std::string> charging_problem(double charge_below, double charge_to) {
  if (charge_below > 0 && !(charge_to > charge_below)) {
    return fmt::format("the state of charge a charge aims at ({}) must be above the one under which the "
                       "vehicle charges ({})",
                       charge_to, charge_below);
  }
  return std::nullopt;
}

}  // namespace drover::logical_agent
