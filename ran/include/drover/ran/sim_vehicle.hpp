#pragma once
// A simulated vehicle: the model behind `drover ran-sim`, every demo and every test that
// needs a vehicle. Deterministic: it moves only when step() is called, by exactly the time
// given, so a runner drives it with the shared clock (and thereby its time factor) and a
// test drives it without real time.
//
// Motion: the vehicle turns on the spot at a constant angular speed to face the next
// straight, drives it with a time-optimal trapezoidal speed profile (bounded acceleration
// and deceleration, never above min(command max speed, vehicle max speed)), and turns to
// the target heading when the move names one. Consecutive moves whose straights continue
// in the same direction are driven as one run without stopping in between; the vehicle
// stops exactly at the end of the last move it knows. Positions are exact for any step
// size (the profile is evaluated in closed form).

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <variant>

#include <Eigen/Core>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/ran/commands.hpp"
#include "drover/ran/status.hpp"
#include "drover/ran/validation.hpp"
#include "drover/topology/model.hpp"

namespace drover::ran {

class SpeedProfile;

struct SimVehicleConfig {
  std::string vehicle_id = "sim";
  /// The vehicle outline with its reference point at the origin, facing +x (metres).
  topology::Polygon footprint = default_footprint();
  double max_speed = 1.0;           ///< m/s
  double acceleration = 0.5;        ///< m/s^2
  double deceleration = 0.5;        ///< m/s^2, braking (also when paused or cancelled)
  double angular_speed = 1.0;       ///< rad/s when turning on the spot
  double battery_capacity_wh = 1000;
  double battery_initial_wh = 1000;
  double drain_wh_per_metre = 0.5;  ///< energy used per metre driven
  double charge_wh_per_second = 1.0;
  DurationNs load_duration = seconds_to_ns(5);
  DurationNs unload_duration = seconds_to_ns(5);
  /// Custom actions the vehicle supports, by name, with how long each takes.
  std::map<std::string, DurationNs> custom_actions;
  LoadState initial_load = LoadState::empty;
  /// How much of the footprint (m^2) may stick out of a motion area (round-off and the
  /// sampling of turns); 1e-4 m^2 is a 1 cm square.
  double area_tolerance_m2 = 1e-4;
  /// How far (m) a target may be from its vertex, and a move's start from its edge.
  double position_tolerance = 0.01;
  /// How many ended commands the status keeps listing.
  std::size_t recent_commands = 16;

  /// A 0.6 m x 0.4 m rectangle centred on the reference point.
  static topology::Polygon default_footprint();

  /// Every value checked: speeds, rates and capacities positive and finite, durations
  /// non-negative, initial energy within capacity, the footprint a valid polygon.
  /// \return the first problem found, naming the field.
  Status validate() const;
};

class SimVehicle {
 public:
  /// A vehicle standing at `start` at shared-clock time `now`. With a topology, every move
  /// is also checked against it (check_against_topology).
  /// \return the vehicle, or invalid_argument when the configuration is invalid.
  static Result<SimVehicle> create(SimVehicleConfig config, Pose start, TimeNs now,
                                   std::shared_ptr<const topology::Topology> topology = nullptr);

  SimVehicle(SimVehicle&&) noexcept;
  SimVehicle& operator=(SimVehicle&&) noexcept;
  ~SimVehicle();

  /// Advances the simulation by `dt` >= 0 nanoseconds of shared-clock time, handling
  /// every event inside the step (a straight ends, an action finishes, a stall ends) at
  /// its exact time.
  void step(DurationNs dt);
  /// step(time - now()) when `time` is later than now(); nothing otherwise.
  void advance_to(TimeNs time);

  /// Queues a move. On rejection nothing changes except that the command is listed as
  /// rejected (unless its id duplicates a listed command's id); the vehicle keeps doing
  /// what it did.
  CommandCheck submit(const MoveCommand& command);
  /// Queues an action: load, unload, charge (parameter "target": state of charge to reach,
  /// in (0, 1], default 1) or one of config().custom_actions.
  CommandCheck submit(const ActionCommand& command);
  /// Cancels a command and every command after it. Ended commands and unknown ids are
  /// refused with unknown_command (nothing changes).
  CommandCheck cancel(const CommandId& command);
  void pause();
  void resume();

  /// Fault: the drive stalls; the vehicle stands still (recoverable error "stall") for
  /// `duration`, then resumes by itself.
  void inject_stall(DurationNs duration);
  /// Fault: a protective field is interrupted; the vehicle stops at once (recoverable
  /// error "protective_field") until clear_protective_field().
  void trigger_protective_field();
  void clear_protective_field();
  /// Fault: the battery fails; the vehicle stops at once, every queued command fails, and
  /// it refuses new commands for good (fatal error "battery_failure").
  void fail_battery();
  /// Fault: the link to the commander drops for `duration` (kForever: until
  /// restore_connection). The vehicle brakes to a stop and holds; a runner stops reporting
  /// while connected() is false.
  void lose_connection(DurationNs duration);
  void restore_connection();

  bool connected() const noexcept;
  TimeNs now() const noexcept { return now_; }
  /// Increases on every discrete change (a command's state, an error, pause, load).
  std::uint64_t revision() const noexcept { return revision_; }
  /// A full snapshot; `sequence` is left 0 for the sink to stamp.
  VehicleStatus status() const;
  /// Where the last queued command leaves the vehicle (where a new move starts).
  Pose planned_end() const;
  /// The normalized motion area of the move being executed, or nullptr.
  const MotionArea* active_area() const;
  const SimVehicleConfig& config() const noexcept { return config_; }

 private:
  struct Rotation {
    double target_heading = 0;
  };
  struct Straight {
    Eigen::Vector2d from;
    Eigen::Vector2d to;
    double speed_limit = 0;
    double length() const { return (to - from).norm(); }
  };
  struct Operation {
    ActionKind kind = ActionKind::custom;
    DurationNs duration = 0;       ///< load, unload, custom
    double charge_target_wh = 0;   ///< charge
    DurationNs elapsed = 0;
    bool started = false;
  };
  using Step = std::variant<Rotation, Straight, Operation>;
  struct Task {
    CommandId id;
    CommandState state = CommandState::accepted;
    std::deque<Step> steps;
    MotionArea area;   ///< normalized; empty for actions
    Pose end_pose;
    bool cancel_requested = false;
  };

  SimVehicle(SimVehicleConfig config, Pose start, TimeNs now,
             std::shared_ptr<const topology::Topology> topology);

  bool is_listed(const CommandId& id) const;
  /// Checks every command must pass (unique id, no fatal error); records a rejection.
  CommandCheck admit(const CommandId& id);
  /// Records `rejection` for `id` in the status and returns it.
  CommandCheck reject(const CommandId& id, Rejection rejection);
  CommandCheck check_motion_area(const std::deque<Step>& steps, const Pose& start,
                                 const MotionArea& area, const CommandId& id) const;
  void enqueue(Task task);
  /// Metres along the current run to where task `index` begins; infinity when a turn or
  /// an operation lies between (the vehicle stops before it anyway).
  double distance_to_task(std::size_t index) const;
  void stop_at_once();

  // Stepping.
  const Step* front_step() const;
  TimeNs next_event(TimeNs limit) const;
  void advance_continuous(TimeNs to);
  void handle_events();
  /// When the profile reaches the end of the head straight (of `length`), if it does.
  std::optional<TimeNs> straight_end_time(double length) const;
  bool straight_done(double length) const;
  bool finish_front_step();
  void start_head();
  void plan_motion();
  bool can_move() const noexcept;
  bool can_operate() const noexcept;
  bool stopped() const noexcept;

  // Bookkeeping.
  void end_task(std::size_t index, CommandState state, std::string code, std::string reason);
  void fail_from(std::size_t index, const std::string& code, const std::string& reason);
  void remove_cancelled();
  void record_ended(CommandProgress progress);
  double profile_time(TimeNs time) const;
  void changed() noexcept { ++revision_; }

  SimVehicleConfig config_;
  std::shared_ptr<const topology::Topology> topology_;
  TimeNs now_;
  std::uint64_t revision_ = 1;

  Eigen::Vector2d position_;
  double heading_;
  double speed_ = 0;
  double angular_speed_ = 0;
  double energy_wh_;
  LoadState load_;

  std::deque<Task> tasks_;
  std::deque<CommandProgress> ended_;

  // The speed profile along the straights at the head of the queue.
  std::unique_ptr<SpeedProfile> profile_;
  TimeNs profile_start_ = 0;
  double profile_head_start_ = 0;  ///< profile distance at which the head straight begins
  double head_progress_ = 0;       ///< metres driven along the head straight

  bool replan_ = false;  ///< plan_motion() is due at the end of handle_events()
  bool paused_ = false;
  bool protective_field_ = false;
  bool battery_failed_ = false;
  bool battery_empty_ = false;
  TimeNs stalled_until_ = 0;       ///< stalled while now_ < stalled_until_
  TimeNs disconnected_until_ = 0;  ///< disconnected while now_ < disconnected_until_
};

}  // namespace drover::ran
