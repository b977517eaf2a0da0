// Two RANs reporting for one vehicle against one RAN replaced by its next life
// (agents/ran_runner/src/twin_writer_watch.cpp).

#include <gtest/gtest.h>

#include "drover/ran_runner/twin_writer_watch.hpp"

namespace drover::ran {
namespace {

using namespace std::chrono_literals;
using Kind = TwinWriterWatch::Verdict::Kind;

dds::SampleSource writer(unsigned char id) {
  eprosima::fastrtps::rtps::InstanceHandle_t handle;
  handle.value[0] = id;
  handle.value[15] = 1;
  return dds::SampleSource(handle);
}

TEST(TwinWriterWatch, WritersThatSwitchBackTwiceAreTwinsUntilOneStops) {
  TwinWriterWatch watch(2s);
  const auto t0 = TwinWriterWatch::Clock::time_point{} + 100s;
  const auto a = writer(1), b = writer(2);
  EXPECT_EQ(watch.observe(a, t0).kind, Kind::take);
  // A new writer while the first one reports may be a restarted RAN or a second one: wait.
  const auto waiting = watch.observe(b, t0 + 100ms);
  EXPECT_EQ(waiting.kind, Kind::wait);
  ASSERT_TRUE(waiting.other.has_value());
  EXPECT_TRUE(*waiting.other == a);
  // Back to the first writer once (a late sample of a replaced RAN looks the same): wait.
  EXPECT_EQ(watch.observe(a, t0 + 200ms).kind, Kind::wait);
  // And back again: both are alive.
  const auto twins = watch.observe(b, t0 + 300ms);
  EXPECT_EQ(twins.kind, Kind::twins);
  ASSERT_TRUE(twins.other.has_value());
  EXPECT_TRUE(*twins.other == a);
  EXPECT_EQ(watch.observe(a, t0 + 400ms).kind, Kind::twins);
  // b stops: a alone again once b is out of the window.
  EXPECT_EQ(watch.observe(a, t0 + 1s).kind, Kind::twins);
  EXPECT_EQ(watch.observe(a, t0 + 2500ms).kind, Kind::take);
  EXPECT_EQ(watch.observe(a, t0 + 2600ms).kind, Kind::take);
}

TEST(TwinWriterWatch, ARanReplacedByItsNextLifeIsTakenOnceTheOldOneIsQuiet) {
  TwinWriterWatch watch(2s);
  const auto t0 = TwinWriterWatch::Clock::time_point{} + 100s;
  const auto old_life = writer(1), new_life = writer(2);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(watch.observe(old_life, t0 + i * 100ms).kind, Kind::take);
  // The old life's last status (at 0.4 s) is within the window until 2.4 s.
  for (int i = 5; i <= 24; ++i) EXPECT_EQ(watch.observe(new_life, t0 + i * 100ms).kind, Kind::wait) << i;
  for (int i = 25; i < 40; ++i) EXPECT_EQ(watch.observe(new_life, t0 + i * 100ms).kind, Kind::take) << i;
}

TEST(TwinWriterWatch, ALateSampleOfAReplacedRanIsNoTwin) {
  TwinWriterWatch watch(2s);
  const auto t0 = TwinWriterWatch::Clock::time_point{} + 100s;
  const auto old_life = writer(1), new_life = writer(2);
  // A reader that joins late gets the new life's status, then the old life's last one.
  EXPECT_EQ(watch.observe(new_life, t0).kind, Kind::take);
  EXPECT_EQ(watch.observe(old_life, t0 + 10ms).kind, Kind::wait);
  for (int i = 1; i <= 20; ++i) EXPECT_EQ(watch.observe(new_life, t0 + i * 100ms).kind, Kind::wait) << i;
  EXPECT_EQ(watch.observe(new_life, t0 + 2100ms).kind, Kind::take);
}

TEST(TwinWriterWatch, SamplesOfOneWriterAreEqualAndPrintTheirGuid) {
  EXPECT_TRUE(writer(1) == writer(1));
  EXPECT_FALSE(writer(1) == writer(2));
  EXPECT_NE(writer(1).text(), writer(2).text());
  EXPECT_FALSE(writer(1).text().empty());
}

}  // namespace
}  // namespace drover::ran
