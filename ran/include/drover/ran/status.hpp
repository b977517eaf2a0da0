#pragma once
// What a RAN reports about its vehicle. One VehicleStatus is a complete snapshot: a reader
// that sees only the latest one (DDS state topics keep the last sample) still learns how
// every recent command ended, because ended commands stay in the snapshot for a while.

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drover/common/clock.hpp"
#include "drover/ran/commands.hpp"

namespace drover::ran {

/// Progress of one command. accepted -> running -> finished | failed | cancelled;
/// a command refused on arrival goes straight to rejected.
enum class CommandState { accepted, running, finished, failed, cancelled, rejected };

const char* to_string(CommandState state) noexcept;
std::optional<CommandState> command_state_from_string(const std::string& name) noexcept;
/// finished, failed, cancelled and rejected are terminal: the state never changes again.
constexpr bool is_terminal(CommandState state) noexcept {
  return state != CommandState::accepted && state != CommandState::running;
}

struct CommandProgress {
  CommandId id;
  CommandState state = CommandState::accepted;
  std::string code;    ///< for failed / rejected: machine-readable reason, e.g. "outside_area"
  std::string reason;  ///< for failed / cancelled / rejected: what happened, for people

  friend bool operator==(const CommandProgress&, const CommandProgress&) = default;
};

/// warning: informational, the vehicle works on. recoverable: the vehicle stopped and
/// resumes by itself or once the cause is cleared. fatal: the vehicle cannot go on.
enum class ErrorLevel { warning, recoverable, fatal };

const char* to_string(ErrorLevel level) noexcept;
std::optional<ErrorLevel> error_level_from_string(const std::string& name) noexcept;

/// An active error condition; it stays in the status until it is over.
struct VehicleError {
  ErrorLevel level = ErrorLevel::warning;
  std::string code;  ///< machine-readable, e.g. "stall", "protective_field"
  std::string text;  ///< for people

  friend bool operator==(const VehicleError&, const VehicleError&) = default;
};

enum class LoadState { unknown, empty, loaded };

const char* to_string(LoadState state) noexcept;
std::optional<LoadState> load_state_from_string(const std::string& name) noexcept;

struct BatteryStatus {
  double state_of_charge = 1.0;  ///< 0..1
  double energy_wh = 0;          ///< remaining energy; 0 when the vehicle does not know it
  bool charging = false;

  friend bool operator==(const BatteryStatus&, const BatteryStatus&) = default;
};

/// Speeds at or below these count as standing still (m/s, rad/s). One rule for everyone who
/// asks whether a vehicle moves: the logical agent waiting for a cancelled vehicle to stand,
/// its published VehicleState.moving, and the launcher's fleet monitor.
inline constexpr double kStandingLinearSpeed = 1e-3;
inline constexpr double kStandingAngularSpeed = 1e-3;
inline bool standing_still(double linear_speed, double angular_speed) noexcept {
  return std::abs(linear_speed) <= kStandingLinearSpeed && std::abs(angular_speed) <= kStandingAngularSpeed;
}

struct VehicleStatus {
  std::string vehicle_id;
  std::uint64_t sequence = 0;  ///< stamped by StatusSink::report: 1, 2, 3, ... per sink
  TimeNs time = 0;             ///< shared-clock time the snapshot describes
  Pose pose;
  double linear_speed = 0;   ///< m/s along the heading
  double angular_speed = 0;  ///< rad/s, counter-clockwise positive
  BatteryStatus battery;
  LoadState load = LoadState::unknown;
  bool paused = false;
  /// Commands not yet ended, in execution order, followed by recently ended ones (oldest
  /// first). An ended command stays listed for at least the next few reports.
  std::vector<CommandProgress> commands;
  std::vector<VehicleError> errors;  ///< active error conditions
  topology::Polygon footprint;       ///< the area the vehicle covers at `pose`
  /// The actions the vehicle performs: any of "load", "unload", "charge" and the names of
  /// its custom actions. Empty: not advertised (every action is sent; it may be rejected).
  std::vector<std::string> actions;

  /// The progress of a command, if it is listed.
  const CommandProgress* find_command(const CommandId& id) const;
  /// True when an error of the given code is active.
  bool has_error(const std::string& code) const;
  /// True when `actions` lists `action` ("load", "unload", "charge" or a custom name), or
  /// lists nothing (not advertised).
  bool performs(const std::string& action) const;
};

}  // namespace drover::ran
