#pragma once
// The shared clock of every Drover agent: sim_time = epoch + factor * (steady_now - start),
// as int64 nanoseconds. A launcher hands the same epoch and factor to every process so
// that their clocks agree; factor = 1 in a plant, larger in simulation.

#include <chrono>
#include <cstdint>
#include <limits>

#include "drover/common/result.hpp"

namespace drover {

/// A point on the shared clock, in nanoseconds.
using TimeNs = std::int64_t;
/// A span of shared-clock time, in nanoseconds.
using DurationNs = std::int64_t;

/// The open end of an open-ended interval (a destination held until the next route).
inline constexpr TimeNs kForever = std::numeric_limits<TimeNs>::max();

inline constexpr DurationNs kNsPerSecond = 1'000'000'000;

/// The latest time a shared clock may start at and that agents take as a start time: half
/// the TimeNs range, about 146 years after the clock's zero (the year 2116 on a clock that
/// reads Unix time, as a plant's does), so that such a time plus durations of decades never
/// overflows.
inline constexpr TimeNs kLatestTime = kForever / 2;
/// The fastest a shared clock may run, in shared-clock seconds per real second: from a
/// reading up to kLatestTime it reaches the end of the TimeNs range no sooner than 53 days
/// later (create_at_origin refuses a clock that would read beyond kLatestTime at once).
inline constexpr double kMaxTimeFactor = 1000;

/// Seconds (double) to nanoseconds, rounded to the nearest nanosecond.
constexpr DurationNs seconds_to_ns(double seconds) noexcept {
  return static_cast<DurationNs>(seconds * 1e9 + (seconds >= 0 ? 0.5 : -0.5));
}
/// Nanoseconds to seconds (double).
constexpr double ns_to_seconds(DurationNs ns) noexcept { return static_cast<double>(ns) / 1e9; }

/// The shared simulation clock. Thread-safe: all members are const after construction.
class SharedClock {
 public:
  /// \param epoch_ns  shared-clock time at the moment this clock is constructed
  ///                  (the launcher passes the same value to every process).
  /// \param factor    how many shared-clock seconds pass per real second; in
  ///                  (0, kMaxTimeFactor].
  /// \return the clock, or invalid_argument when factor is out of range or epoch_ns is not
  ///         in [0, kLatestTime].
  static Result<SharedClock> create(TimeNs epoch_ns, double factor);

  /// A clock that read `epoch_ns` at the real Unix time `origin_unix_ns` (ns since 1970)
  /// and runs `factor` times faster since. Processes given the same three values agree on
  /// the time however late each of them starts (up to their hosts' system clocks): this is
  /// how the launcher gives every agent one clock. The system clock is read once, here;
  /// afterwards the clock follows the steady clock, so it never jumps.
  /// \return the clock, or invalid_argument as create() says, when origin_unix_ns is not
  ///         in [0, kLatestTime], or when the clock would read beyond +-kLatestTime now
  ///         (an origin long past at a high factor).
  static Result<SharedClock> create_at_origin(TimeNs epoch_ns, double factor, TimeNs origin_unix_ns);

  /// A clock with epoch = the Unix time now and factor 1 (a plant).
  static SharedClock wall();

  /// The Unix time now, in nanoseconds (the system clock).
  static TimeNs unix_now() noexcept;

  /// Current shared-clock time in nanoseconds (monotonic: never goes backwards).
  TimeNs now() const noexcept;

  /// Real duration that corresponds to a shared-clock duration (for sleeps and timers).
  std::chrono::nanoseconds to_real(DurationNs sim) const noexcept;

  /// Shared-clock duration that corresponds to a real duration.
  DurationNs to_sim(std::chrono::nanoseconds real) const noexcept;

  TimeNs epoch() const noexcept { return epoch_ns_; }
  double factor() const noexcept { return factor_; }

 private:
  SharedClock(TimeNs epoch_ns, double factor, std::chrono::steady_clock::time_point start)
      : epoch_ns_(epoch_ns), factor_(factor), start_(start) {}

  TimeNs epoch_ns_;
  double factor_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace drover
