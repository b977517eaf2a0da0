#include "ran/src/speed_profile.hpp"

#include <algorithm>
#include <cmath>

namespace drover::ran {

namespace {
/// Slack for floating-point round-off when comparing speeds (m/s).
constexpr double kSpeedSlack = 1e-9;
}  // namespace

std::optional<SpeedProfile> SpeedProfile::plan(std::span<const ProfileSegment> segments,
                                               double start_speed, double acceleration,
                                               double deceleration) {
  const std::size_t n = segments.size();
  if (n == 0) {
    if (start_speed > kSpeedSlack) return std::nullopt;
    return rest();
  }
  // Backward pass: the highest speed at each boundary from which the vehicle can still
  // slow down for every later limit and stop at the end.
  std::vector<double> backward(n + 1, 0.0);
  for (std::size_t i = n; i-- > 0;) {
    const double reachable =
        std::sqrt(backward[i + 1] * backward[i + 1] + 2 * deceleration * segments[i].length);
    double limit = segments[i].speed_limit;
    if (i > 0) limit = std::min(limit, segments[i - 1].speed_limit);
    backward[i] = std::min(limit, reachable);
  }
  // The first segment's limit does not bind the start (the vehicle already respects it);
  // only the braking distance can make the plan infeasible.
  const double stoppable =
      std::sqrt(backward[1] * backward[1] + 2 * deceleration * segments[0].length);
  if (start_speed > stoppable + kSpeedSlack) return std::nullopt;
  // Forward pass: the highest speed at each boundary reachable from the start.
  std::vector<double> boundary(n + 1, 0.0);
  boundary[0] = start_speed;
  for (std::size_t i = 0; i < n; ++i) {
    const double reachable =
        std::sqrt(boundary[i] * boundary[i] + 2 * acceleration * segments[i].length);
    boundary[i + 1] = std::min(backward[i + 1], reachable);
  }

  SpeedProfile profile;
  for (std::size_t i = 0; i < n; ++i) {
    const double u = boundary[i];
    const double w = boundary[i + 1];
    const double length = segments[i].length;
    if (length <= 0) continue;
    // The peak speed of a trapezoid u -> peak -> w over `length`, capped at the limit.
    const double peak_squared =
        (2 * acceleration * deceleration * length + deceleration * u * u + acceleration * w * w) /
        (acceleration + deceleration);
    const double peak =
        std::max({std::min(segments[i].speed_limit, std::sqrt(peak_squared)), u, w});
    const double accelerate_distance = (peak * peak - u * u) / (2 * acceleration);
    const double decelerate_distance = (peak * peak - w * w) / (2 * deceleration);
    const double cruise_distance = std::max(0.0, length - accelerate_distance - decelerate_distance);
    profile.append(u, acceleration, (peak - u) / acceleration);
    if (peak > 0) profile.append(peak, 0, cruise_distance / peak);
    profile.append(peak, -deceleration, (peak - w) / deceleration);
  }
  return profile;
}

SpeedProfile SpeedProfile::brake(double start_speed, double deceleration) {
  SpeedProfile profile;
  profile.append(start_speed, -deceleration, start_speed / deceleration);
  return profile;
}

void SpeedProfile::append(double start_speed, double acceleration, double duration) {
  if (!(duration > 0)) return;
  Phase phase;
  phase.start_speed = start_speed;
  phase.acceleration = acceleration;
  phase.duration = duration;
  if (!phases_.empty()) {
    const Phase& last = phases_.back();
    phase.start_time = last.start_time + last.duration;
    phase.start_distance = last.start_distance + last.start_speed * last.duration +
                           0.5 * last.acceleration * last.duration * last.duration;
  }
  phases_.push_back(phase);
}

double SpeedProfile::duration() const noexcept {
  if (phases_.empty()) return 0;
  return phases_.back().start_time + phases_.back().duration;
}

double SpeedProfile::distance() const noexcept { return distance_at(duration()); }

const SpeedProfile::Phase* SpeedProfile::phase_at(double t) const noexcept {
  if (phases_.empty()) return nullptr;
  // The last phase that starts at or before t.
  auto found = std::upper_bound(phases_.begin(), phases_.end(), t,
                                [](double time, const Phase& p) { return time < p.start_time; });
  if (found == phases_.begin()) return &phases_.front();
  return &*std::prev(found);
}

double SpeedProfile::distance_at(double t) const noexcept {
  const Phase* phase = phase_at(t);
  if (phase == nullptr) return 0;
  const double tau = std::clamp(t - phase->start_time, 0.0, phase->duration);
  return phase->start_distance + phase->start_speed * tau + 0.5 * phase->acceleration * tau * tau;
}

double SpeedProfile::speed_at(double t) const noexcept {
  if (t >= duration()) return 0;
  const Phase* phase = phase_at(t);
  if (phase == nullptr) return 0;
  const double tau = std::clamp(t - phase->start_time, 0.0, phase->duration);
  return std::max(0.0, phase->start_speed + phase->acceleration * tau);
}

double SpeedProfile::time_at(double s) const noexcept {
  if (phases_.empty() || s <= 0) return 0;
  if (s >= distance()) return duration();
  // The first phase whose end lies at or beyond s.
  for (const Phase& phase : phases_) {
    const double end = phase.start_distance + phase.start_speed * phase.duration +
                       0.5 * phase.acceleration * phase.duration * phase.duration;
    if (end < s) continue;
    const double remaining = s - phase.start_distance;
    double tau;
    if (std::abs(phase.acceleration) < 1e-12) {
      tau = phase.start_speed > 0 ? remaining / phase.start_speed : 0;
    } else {
      // 0.5 a tau^2 + v0 tau - remaining = 0, the root reached first.
      const double discriminant =
          std::max(0.0, phase.start_speed * phase.start_speed + 2 * phase.acceleration * remaining);
      tau = (std::sqrt(discriminant) - phase.start_speed) / phase.acceleration;
    }
    return phase.start_time + std::clamp(tau, 0.0, phase.duration);
  }
  return duration();
}

}  // namespace drover::ran
