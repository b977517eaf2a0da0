// The time-optimal speed profile the simulated vehicle drives with.

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "ran/src/speed_profile.hpp"
#include "tests/ran/sim_world.hpp"

namespace drover::ran {
namespace {

TEST(SpeedProfile, TrapezoidMatchesTheFormula) {
  const std::vector<ProfileSegment> segments{{10.0, 1.0}};
  const auto profile = SpeedProfile::plan(segments, 0.0, 0.5, 0.25);
  ASSERT_TRUE(profile);
  // 2 s accelerating (1 m), 4 s braking (2 m), 7 m cruising at 1 m/s.
  EXPECT_NEAR(profile->duration(), 2.0 + 7.0 + 4.0, 1e-9);
  EXPECT_NEAR(profile->duration(), test::trapezoid_time(10.0, 1.0, 0.5, 0.25), 1e-9);
  EXPECT_NEAR(profile->distance(), 10.0, 1e-9);
  EXPECT_NEAR(profile->speed_at(5.0), 1.0, 1e-12);
  EXPECT_NEAR(profile->distance_at(2.0), 1.0, 1e-12);
  EXPECT_EQ(profile->speed_at(profile->duration()), 0.0);
}

TEST(SpeedProfile, ShortSegmentIsATriangleBelowTheLimit) {
  const std::vector<ProfileSegment> segments{{1.0, 5.0}};
  const auto profile = SpeedProfile::plan(segments, 0.0, 0.5, 0.5);
  ASSERT_TRUE(profile);
  EXPECT_NEAR(profile->duration(), test::trapezoid_time(1.0, 5.0, 0.5, 0.5), 1e-9);
  EXPECT_NEAR(profile->speed_at(profile->duration() / 2), std::sqrt(0.5), 1e-9);
}

TEST(SpeedProfile, SlowsDownForALowerLimitAheadAndStopsAtTheEnd) {
  const std::vector<ProfileSegment> segments{{6.0, 2.0}, {4.0, 0.5}, {6.0, 1.5}};
  const auto profile = SpeedProfile::plan(segments, 0.0, 1.0, 1.0);
  ASSERT_TRUE(profile);
  EXPECT_NEAR(profile->distance(), 16.0, 1e-9);
  for (double t = 0; t <= profile->duration(); t += 0.001) {
    const double s = profile->distance_at(t);
    const double limit = s < 6.0 ? 2.0 : s < 10.0 ? 0.5 : 1.5;
    // At a boundary the speed is below both neighbours' limits.
    const double boundary_limit = std::abs(s - 6.0) < 1e-6 || std::abs(s - 10.0) < 1e-6 ? 0.5 : limit;
    EXPECT_LE(profile->speed_at(t), boundary_limit + 1e-6) << "t = " << t << ", s = " << s;
  }
}

TEST(SpeedProfile, TimeAtInvertsDistanceAt) {
  const std::vector<ProfileSegment> segments{{3.0, 1.0}, {2.0, 2.0}};
  const auto profile = SpeedProfile::plan(segments, 0.4, 0.7, 0.9);
  ASSERT_TRUE(profile);
  for (double s = 0; s <= 5.0; s += 0.125) {
    EXPECT_NEAR(profile->distance_at(profile->time_at(s)), s, 1e-9);
  }
}

TEST(SpeedProfile, TooFastToStopIsInfeasible) {
  const std::vector<ProfileSegment> segments{{1.0, 3.0}};
  // Braking from 2 m/s at 1 m/s^2 takes 2 m.
  EXPECT_FALSE(SpeedProfile::plan(segments, 2.0, 1.0, 1.0));
  const auto brake = SpeedProfile::brake(2.0, 1.0);
  EXPECT_NEAR(brake.distance(), 2.0, 1e-12);
  EXPECT_NEAR(brake.duration(), 2.0, 1e-12);
}

TEST(SpeedProfile, RandomPathsRespectLimitsAndAccelerations) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> length(0.05, 8.0), limit(0.1, 2.5), rate(0.2, 2.0);
  for (int round = 0; round < 200; ++round) {
    std::vector<ProfileSegment> segments(1 + round % 5);
    double total = 0;
    for (auto& segment : segments) {
      segment = {length(random), limit(random)};
      total += segment.length;
    }
    const double acceleration = rate(random), deceleration = rate(random);
    const auto profile = SpeedProfile::plan(segments, 0.0, acceleration, deceleration);
    ASSERT_TRUE(profile);
    EXPECT_NEAR(profile->distance(), total, 1e-6);
    const double dt = profile->duration() / 500;
    double previous = 0;
    for (int i = 1; i <= 500; ++i) {
      const double t = i * dt;
      const double v = profile->speed_at(t);
      EXPECT_LE(v - previous, acceleration * dt + 1e-9);
      EXPECT_LE(previous - v, deceleration * dt + 1e-9);
      double s = profile->distance_at(t), start = 0;
      for (const auto& segment : segments) {
        if (s <= start + segment.length + 1e-9) {
          EXPECT_LE(v, segment.speed_limit + 1e-6);
          break;
        }
        start += segment.length;
      }
      previous = v;
    }
  }
}

}  // namespace
}  // namespace drover::ran
