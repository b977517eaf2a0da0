// The SDK pieces an integrator uses directly: footprints and motion areas, command
// validation, enum names, the status sink's sequence numbers, and a driver behind the
// VehicleDriver interface.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <thread>
#include <vector>

#include <boost/geometry.hpp>
#include <gtest/gtest.h>

#include "drover/ran/motion_area.hpp"
#include "drover/ran/sim_driver.hpp"
#include "drover/ran/validation.hpp"
#include "tests/ran/sim_world.hpp"

namespace drover::ran {
namespace {

namespace bg = boost::geometry;
using topology::Polygon;

Polygon square(double x0, double y0, double x1, double y1) {
  return Polygon{{{x0, y0}, {x0, y1}, {x1, y1}, {x1, y0}, {x0, y0}}};
}

TEST(MotionArea, FootprintIsRotatedThenTranslated) {
  const Polygon vehicle = square(-0.5, -0.1, 0.5, 0.1);
  const auto placed = footprint_at(vehicle, Pose{2, 3, std::numbers::pi / 2});
  double min_x = 1e9, max_x = -1e9, min_y = 1e9, max_y = -1e9;
  for (const auto& corner : placed.outer()) {
    min_x = std::min(min_x, corner.x());
    max_x = std::max(max_x, corner.x());
    min_y = std::min(min_y, corner.y());
    max_y = std::max(max_y, corner.y());
  }
  EXPECT_NEAR(min_x, 1.9, 1e-12);
  EXPECT_NEAR(max_x, 2.1, 1e-12);
  EXPECT_NEAR(min_y, 2.5, 1e-12);
  EXPECT_NEAR(max_y, 3.5, 1e-12);
  EXPECT_NEAR(bg::area(placed), bg::area(vehicle), 1e-12);
}

TEST(MotionArea, OverlappingPartsMergeAndOutsideAreaIsMeasured) {
  MotionArea parts{square(0, 0, 2, 2), square(1, 0, 4, 2)};
  const auto merged = normalized_area(parts);
  ASSERT_EQ(merged.size(), 1u);
  EXPECT_NEAR(bg::area(merged), 8.0, 1e-12);
  EXPECT_NEAR(area_outside(square(3, 1, 5, 2), merged), 1.0, 1e-12);
  EXPECT_NEAR(area_outside(square(0.5, 0.5, 3.5, 1.5), merged), 0.0, 1e-12);
  // Disjoint parts stay two polygons.
  EXPECT_EQ(normalized_area(MotionArea{square(0, 0, 1, 1), square(5, 5, 6, 6)}).size(), 2u);
}

TEST(MotionArea, TranslationSweepCoversTheWayBetween) {
  const auto swept = swept_by_translation(square(0, 0, 1, 1), 3, 0);
  EXPECT_NEAR(bg::area(swept), 4.0, 1e-12);
  // A gap in the middle of the way is caught, though start and end fit.
  const auto area = normalized_area(MotionArea{square(0, 0, 1.5, 1), square(2.5, 0, 4, 1)});
  EXPECT_GT(area_outside(swept, area), 0.9);
}

TEST(Validation, CheckAgainstTopologyAcceptsAStartAlongTheEdgeOrOnItsOriginVertex) {
  const auto world = test::world();
  const auto command = test::move(*world, "m", "B", "bc", "C", 1.0);
  EXPECT_TRUE(check_against_topology(command, *world, Pose{5, 0, 0}, 0.01));
  EXPECT_TRUE(check_against_topology(command, *world, Pose{7.5, 0.005, 0}, 0.01));
  const auto off = check_against_topology(command, *world, Pose{7.5, 0.5, 0}, 0.01);
  ASSERT_FALSE(off);
  EXPECT_EQ(off.error().code, rejection_code::kEdgeMismatch);
  // Driving west from C, braked to a stop 0.3 m past B, on ab: it stands on B (inside its
  // footprint, a 1 m square), so a move from B over bc starts there. Beyond the footprint,
  // off bc, it does not.
  EXPECT_TRUE(check_against_topology(command, *world, Pose{4.7, 0, std::numbers::pi}, 0.01));
  const auto beyond = check_against_topology(command, *world, Pose{4.3, 0, std::numbers::pi}, 0.01);
  ASSERT_FALSE(beyond);
  EXPECT_EQ(beyond.error().code, rejection_code::kEdgeMismatch);
  // A turn on the spot (no edge) must start at the target.
  auto turn = test::move(*world, "t", "C", "", "C", 1.0, 1.0);
  EXPECT_TRUE(check_against_topology(turn, *world, Pose{10, 0, 0}, 0.01));
  EXPECT_FALSE(check_against_topology(turn, *world, Pose{9, 0, 0}, 0.01));
}

TEST(Names, RoundTrip) {
  for (auto state : {CommandState::accepted, CommandState::running, CommandState::finished,
                     CommandState::failed, CommandState::cancelled, CommandState::rejected}) {
    EXPECT_EQ(command_state_from_string(to_string(state)), state);
  }
  for (auto kind : {ActionKind::load, ActionKind::unload, ActionKind::charge, ActionKind::custom}) {
    EXPECT_EQ(action_kind_from_string(to_string(kind)), kind);
  }
  for (auto level : {ErrorLevel::warning, ErrorLevel::recoverable, ErrorLevel::fatal}) {
    EXPECT_EQ(error_level_from_string(to_string(level)), level);
  }
  for (auto load : {LoadState::unknown, LoadState::empty, LoadState::loaded}) {
    EXPECT_EQ(load_state_from_string(to_string(load)), load);
  }
  EXPECT_FALSE(command_state_from_string("done"));
}

class RecordingSink final : public StatusSink {
 public:
  std::vector<VehicleStatus> reports;

 protected:
  void deliver(const VehicleStatus& status) override { reports.push_back(status); }
};

TEST(StatusSink, StampsIncreasingSequenceNumbersAcrossThreads) {
  RecordingSink sink;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&] {
      for (int i = 0; i < 250; ++i) sink.report(VehicleStatus{});
    });
  }
  for (auto& thread : threads) thread.join();
  ASSERT_EQ(sink.reports.size(), 1000u);
  for (std::size_t i = 0; i < sink.reports.size(); ++i) {
    EXPECT_EQ(sink.reports[i].sequence, i + 1);
  }
}

TEST(SimDriver, ReportsEveryCommandAndFollowsTheCallersClock) {
  const auto world = test::world();
  SimDriver driver(test::vehicle_at(world, "A"));
  RecordingSink sink;
  driver.start(sink, 0);
  ASSERT_EQ(sink.reports.size(), 1u);
  EXPECT_EQ(sink.reports.back().vehicle_id, "sim");

  driver.on_move(test::move(*world, "m1", "A", "ab", "B", 1.0), seconds_to_ns(1));
  EXPECT_EQ(sink.reports.back().find_command("m1")->state, CommandState::running);
  EXPECT_EQ(sink.reports.back().time, seconds_to_ns(1));

  driver.on_move(test::move(*world, "bad", "C", "cd", "D", 1.0), seconds_to_ns(2));
  EXPECT_EQ(sink.reports.back().find_command("bad")->state, CommandState::rejected);

  driver.on_tick(seconds_to_ns(3));  // 2 s after the move started: 1 m driven
  EXPECT_NEAR(sink.reports.back().pose.x, 1.0, 1e-9);
  driver.on_pause(seconds_to_ns(4));
  EXPECT_TRUE(sink.reports.back().paused);
  driver.on_resume(seconds_to_ns(10));
  EXPECT_FALSE(sink.reports.back().paused);
  driver.on_cancel("m1", seconds_to_ns(10));
  driver.on_tick(seconds_to_ns(20));
  EXPECT_EQ(sink.reports.back().find_command("m1")->state, CommandState::cancelled);

  driver.vehicle().lose_connection(kForever);
  const auto reported = sink.reports.size();
  driver.on_tick(seconds_to_ns(21));
  EXPECT_EQ(sink.reports.size(), reported);  // silent while the link is down
  for (std::size_t i = 1; i < sink.reports.size(); ++i) {
    EXPECT_EQ(sink.reports[i].sequence, sink.reports[i - 1].sequence + 1);
    EXPECT_GE(sink.reports[i].time, sink.reports[i - 1].time);
  }
}

}  // namespace
}  // namespace drover::ran
