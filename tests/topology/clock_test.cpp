#include <cmath>

#include <gtest/gtest.h>

#include "drover/common/clock.hpp"

namespace drover {
namespace {

TEST(SharedClock, RejectsNonPositiveFactor) {
  EXPECT_FALSE(SharedClock::create(0, 0.0).has_value());
  EXPECT_FALSE(SharedClock::create(0, -2.0).has_value());
  EXPECT_EQ(SharedClock::create(0, -2.0).error().code, ErrorCode::invalid_argument);
  EXPECT_FALSE(SharedClock::create(0, std::nan("")).has_value());
}

// Faster clocks, or later epochs, would overflow int64 nanoseconds within weeks.
TEST(SharedClock, RejectsFactorsAndTimesItCouldOverflowWith) {
  EXPECT_TRUE(SharedClock::create(kLatestTime, kMaxTimeFactor).has_value());
  const auto fast = SharedClock::create(0, kMaxTimeFactor * 1.5);
  ASSERT_FALSE(fast.has_value());
  EXPECT_NE(fast.error().message.find("at most 1000, got 1500"), std::string::npos) << fast.error().message;
  EXPECT_FALSE(SharedClock::create(0, INFINITY).has_value());
  EXPECT_FALSE(SharedClock::create(kLatestTime + 1, 1.0).has_value());
  EXPECT_FALSE(SharedClock::create(-1, 1.0).has_value());
  EXPECT_FALSE(SharedClock::create_at_origin(0, 1.0, -1).has_value());
  EXPECT_FALSE(SharedClock::create_at_origin(0, 1.0, kLatestTime + 1).has_value());
  // Epoch and origin in range, but at factor 6 the Unix time since 1970 is beyond int64.
  const auto since_1970 = SharedClock::create_at_origin(0, 6.0, 0);
  ASSERT_FALSE(since_1970.has_value());
  EXPECT_NE(since_1970.error().message.find("would read"), std::string::npos) << since_1970.error().message;
  // An origin in the future (another host's system clock ahead) reads a little before the epoch.
  // (10 s ahead: however slow the host is between the two readings, it reads before 0.)
  auto ahead = SharedClock::create_at_origin(0, 10.0, SharedClock::unix_now() + 10 * kNsPerSecond);
  ASSERT_TRUE(ahead.has_value());
  EXPECT_LT(ahead->now(), 0);
}

TEST(SharedClock, ScalesRealTimeByFactor) {
  auto clock = SharedClock::create(5 * kNsPerSecond, 10.0);
  ASSERT_TRUE(clock.has_value());
  EXPECT_GE(clock->now(), 5 * kNsPerSecond);
  EXPECT_EQ(clock->to_sim(std::chrono::milliseconds(100)), kNsPerSecond);
  EXPECT_EQ(clock->to_real(kNsPerSecond), std::chrono::milliseconds(100));
}

TEST(SharedClock, NeverGoesBackwards) {
  auto clock = SharedClock::create(0, 1000.0);
  ASSERT_TRUE(clock.has_value());
  TimeNs previous = clock->now();
  for (int i = 0; i < 1000; ++i) {
    const TimeNs now = clock->now();
    EXPECT_GE(now, previous);
    previous = now;
  }
}

TEST(SharedClock, ClocksCreatedLaterFromOneOriginAgree) {
  // Two processes started at different real times, given the same epoch, factor and
  // origin: the later one must not lag behind by (its start delay) x factor.
  const TimeNs origin = SharedClock::unix_now() - 2 * kNsPerSecond;  // started 2 s ago
  auto clock = SharedClock::create_at_origin(100 * kNsPerSecond, 50.0, origin);
  ASSERT_TRUE(clock.has_value());
  // 2 real seconds at factor 50 have passed: 100 s of shared-clock time, give or take
  // the time this test takes to get here (bounded generously, never slept).
  EXPECT_GE(clock->now(), 200 * kNsPerSecond);
  EXPECT_LT(clock->now(), 300 * kNsPerSecond);
  EXPECT_FALSE(SharedClock::create_at_origin(0, 0.0, origin).has_value());
}

TEST(Seconds, RoundTripsThroughNanoseconds) {
  EXPECT_EQ(seconds_to_ns(1.5), 1'500'000'000);
  EXPECT_EQ(seconds_to_ns(-0.25), -250'000'000);
  EXPECT_DOUBLE_EQ(ns_to_seconds(2'500'000'000), 2.5);
}

}  // namespace
}  // namespace drover
