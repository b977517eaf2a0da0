#pragma once
// Time-optimal speed profiles along a path of straight segments with per-segment speed
// limits, bounded acceleration and deceleration: trapezoids (or triangles) per segment,
// joined at the highest boundary speeds both limits allow. Evaluated in closed form, so a
// vehicle stepped with any time step is exactly where the profile says.

#include <optional>
#include <span>
#include <vector>

namespace drover::ran {

struct ProfileSegment {
  double length = 0;       ///< m, >= 0
  double speed_limit = 0;  ///< m/s, > 0
};

class SpeedProfile {
 public:
  /// The fastest way over `segments` starting at `start_speed` and ending at rest exactly
  /// at the end of the last segment, never above a segment's limit (at a boundary, below
  /// both neighbours' limits).
  /// \return nullopt when the vehicle is too fast to stop by the end even braking at once
  ///         (the caller then brakes instead).
  static std::optional<SpeedProfile> plan(std::span<const ProfileSegment> segments,
                                          double start_speed, double acceleration,
                                          double deceleration);

  /// Braking at `deceleration` from `start_speed` to rest.
  static SpeedProfile brake(double start_speed, double deceleration);

  /// Standing still.
  static SpeedProfile rest() { return SpeedProfile{}; }

  double duration() const noexcept;  ///< s until rest
  double distance() const noexcept;  ///< m covered until rest
  /// Distance covered after `t` seconds (clamped to [0, duration()]).
  double distance_at(double t) const noexcept;
  /// Speed after `t` seconds (0 after duration()).
  double speed_at(double t) const noexcept;
  /// The earliest time at which distance_at reaches `s` (clamped to [0, distance()]).
  double time_at(double s) const noexcept;

 private:
  /// Constant acceleration from (start_time, start_distance, start_speed) for `duration`.
  struct Phase {
    double start_time = 0;
    double start_distance = 0;
    double start_speed = 0;
    double acceleration = 0;
    double duration = 0;
  };
  void append(double start_speed, double acceleration, double duration);
  const Phase* phase_at(double t) const noexcept;

  std::vector<Phase> phases_;
};

}  // namespace drover::ran
