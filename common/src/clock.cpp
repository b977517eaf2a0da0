#include "drover/common/clock.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

namespace drover {

Result<SharedClock> SharedClock::create(TimeNs epoch_ns, double factor) {
  if (!(factor > 0.0 && factor <= kMaxTimeFactor)) {
    return fail(ErrorCode::invalid_argument,
                fmt::format("time factor must be > 0 and at most {}, got {}", kMaxTimeFactor, factor));
  }
  if (epoch_ns < 0 || epoch_ns > kLatestTime) {
    return fail(ErrorCode::invalid_argument,
                fmt::format("epoch must be from 0 to {} ns, got {}", kLatestTime, epoch_ns));
  }
  return SharedClock(epoch_ns, factor, std::chrono::steady_clock::now());
}

Result<SharedClock> SharedClock::create_at_origin(TimeNs epoch_ns, double factor,
                                                  TimeNs origin_unix_ns) {
  auto clock = create(epoch_ns, factor);
  if (!clock) return clock;
  if (origin_unix_ns < 0 || origin_unix_ns > kLatestTime) {
    return fail(ErrorCode::invalid_argument,
                fmt::format("clock origin must be from 0 to {} ns, got {}", kLatestTime, origin_unix_ns));
  }
  // The steady-clock instant at which the clock read epoch_ns: as long before now as the
  // origin lies before the Unix time now (after it, for an origin in the future).
  const auto since_origin = std::chrono::nanoseconds(unix_now() - origin_unix_ns);
  // What it reads now must be a time too: an origin long past at a high factor would put
  // it beyond int64 at once. (Slightly negative is fine: a host whose system clock is
  // behind the launcher's, with epoch 0.)
  const double reading = static_cast<double>(epoch_ns) + factor * static_cast<double>(since_origin.count());
  if (!(std::abs(reading) <= static_cast<double>(kLatestTime))) {
    return fail(ErrorCode::invalid_argument,
                fmt::format("a clock that read {} ns at Unix time {} ns and runs {} times as fast would "
                            "read {:.0f} ns now, beyond {} ns",
                            epoch_ns, origin_unix_ns, factor, reading, kLatestTime));
  }
  return SharedClock(epoch_ns, factor, std::chrono::steady_clock::now() - since_origin);
}

SharedClock SharedClock::wall() {
  return SharedClock(unix_now(), 1.0, std::chrono::steady_clock::now());
}

TimeNs SharedClock::unix_now() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

TimeNs SharedClock::now() const noexcept {
  const auto elapsed = std::chrono::steady_clock::now() - start_;
  return epoch_ns_ + to_sim(std::chrono::duration_cast<std::chrono::nanoseconds>(elapsed));
}

std::chrono::nanoseconds SharedClock::to_real(DurationNs sim) const noexcept {
  return std::chrono::nanoseconds(static_cast<std::int64_t>(static_cast<double>(sim) / factor_));
}

DurationNs SharedClock::to_sim(std::chrono::nanoseconds real) const noexcept {
  return static_cast<DurationNs>(static_cast<double>(real.count()) * factor_);
}

}  // namespace drover
