// Faults, pause and cancel on the simulated vehicle.

#include <gtest/gtest.h>

#include "tests/ran/sim_world.hpp"

namespace drover::ran {
namespace {

using test::move;
using test::state_of;
using test::step_until;
using test::vehicle_at;

constexpr DurationNs kMs = 1'000'000;

const VehicleError* error_of(const VehicleStatus& status, const std::string& code) {
  for (const auto& error : status.errors) {
    if (error.code == code) return &error;
  }
  return nullptr;
}

TEST(SimFaults, StallStandsStillForItsDurationThenResumes) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  vehicle.step(seconds_to_ns(3));
  const double x = vehicle.status().pose.x;
  vehicle.inject_stall(seconds_to_ns(4));
  auto status = vehicle.status();
  ASSERT_NE(error_of(status, "stall"), nullptr);
  EXPECT_EQ(error_of(status, "stall")->level, ErrorLevel::recoverable);
  EXPECT_EQ(status.linear_speed, 0);
  for (int i = 0; i < 39; ++i) {
    vehicle.step(100 * kMs);
    EXPECT_DOUBLE_EQ(vehicle.status().pose.x, x);
  }
  vehicle.step(100 * kMs);
  EXPECT_FALSE(vehicle.status().has_error("stall"));
  EXPECT_EQ(state_of(vehicle, "m1"), CommandState::running);
  ASSERT_TRUE(step_until(
      vehicle, [&] { return state_of(vehicle, "m1") == CommandState::finished; }, kMs,
      seconds_to_ns(60)));
  // The rest of the move from rest: 3 m at 1 m/s with 1 m ramps, after 3 s + 4 s.
  EXPECT_NEAR(ns_to_seconds(vehicle.now()), 7 + test::trapezoid_time(5 - x, 1, 0.5, 0.5), 0.0011);
  EXPECT_DOUBLE_EQ(vehicle.status().pose.x, 5.0);
}

TEST(SimFaults, ProtectiveFieldStopsAtOnceUntilCleared) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  vehicle.step(seconds_to_ns(2.5));
  vehicle.trigger_protective_field();
  const double x = vehicle.status().pose.x;
  EXPECT_EQ(vehicle.status().linear_speed, 0);
  EXPECT_EQ(error_of(vehicle.status(), "protective_field")->level, ErrorLevel::recoverable);
  vehicle.step(seconds_to_ns(100));
  EXPECT_DOUBLE_EQ(vehicle.status().pose.x, x);
  EXPECT_EQ(state_of(vehicle, "m1"), CommandState::running);
  vehicle.clear_protective_field();
  EXPECT_FALSE(vehicle.status().has_error("protective_field"));
  ASSERT_TRUE(step_until(
      vehicle, [&] { return state_of(vehicle, "m1") == CommandState::finished; }, 10 * kMs,
      seconds_to_ns(60)));
  EXPECT_DOUBLE_EQ(vehicle.status().pose.x, 5.0);
}

TEST(SimFaults, BatteryFailureIsFatalFailsEverythingAndRefusesNewCommands) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  vehicle.step(seconds_to_ns(2));
  vehicle.fail_battery();
  auto status = vehicle.status();
  EXPECT_EQ(error_of(status, "battery_failure")->level, ErrorLevel::fatal);
  EXPECT_EQ(status.find_command("m1")->state, CommandState::failed);
  EXPECT_EQ(status.find_command("m1")->code, "battery_failure");
  EXPECT_EQ(status.find_command("m2")->state, CommandState::failed);
  EXPECT_EQ(status.linear_speed, 0);
  const double x = status.pose.x;
  vehicle.step(seconds_to_ns(30));
  EXPECT_DOUBLE_EQ(vehicle.status().pose.x, x);
  const auto refused = vehicle.submit(ActionCommand{"c", ActionKind::charge, "", {}});
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, rejection_code::kNotReady);
  EXPECT_EQ(vehicle.status().find_command("c")->state, CommandState::rejected);
}

TEST(SimFaults, LostConnectionBrakesHoldsAndResumesWhenRestored) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  vehicle.step(seconds_to_ns(3));  // cruising at 1 m/s at x = 2
  vehicle.lose_connection(seconds_to_ns(10));
  EXPECT_FALSE(vehicle.connected());
  vehicle.step(seconds_to_ns(2));  // braking at 0.5 m/s^2 takes 2 s and 1 m
  EXPECT_EQ(vehicle.status().linear_speed, 0);
  EXPECT_NEAR(vehicle.status().pose.x, 3.0, 1e-9);
  vehicle.step(seconds_to_ns(7.9));
  EXPECT_NEAR(vehicle.status().pose.x, 3.0, 1e-9);
  EXPECT_FALSE(vehicle.connected());
  vehicle.step(seconds_to_ns(0.1));
  EXPECT_TRUE(vehicle.connected());
  ASSERT_TRUE(step_until(
      vehicle, [&] { return state_of(vehicle, "m1") == CommandState::finished; }, 10 * kMs,
      seconds_to_ns(60)));

  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  vehicle.lose_connection(kForever);
  vehicle.step(seconds_to_ns(1000));
  EXPECT_FALSE(vehicle.connected());
  vehicle.restore_connection();
  EXPECT_TRUE(vehicle.connected());
}

TEST(SimFaults, AStallOfAnyLengthFromTheNetworkNeitherWrapsNorEndsEarly) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  vehicle.step(seconds_to_ns(1));
  vehicle.inject_stall(kForever);  // before, now + duration wrapped: the stall ended at once
  vehicle.step(seconds_to_ns(1000));
  EXPECT_TRUE(vehicle.status().has_error("stall"));
  EXPECT_EQ(state_of(vehicle, "m1"), CommandState::running);
}

TEST(SimMotion, AMoveAtACrawlRunsWithoutOverflowingItsEndTime) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  // 5 m at 1e-12 m/s would take 5e12 s: more ns than an int64 holds.
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1e-12)));
  vehicle.step(seconds_to_ns(10));
  EXPECT_EQ(state_of(vehicle, "m1"), CommandState::running);
  EXPECT_LT(vehicle.status().pose.x, 1e-9);
}

TEST(SimPause, BrakesHoldsAndResumes) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  vehicle.step(seconds_to_ns(3));
  vehicle.pause();
  EXPECT_TRUE(vehicle.status().paused);
  vehicle.step(seconds_to_ns(2));
  EXPECT_EQ(vehicle.status().linear_speed, 0);
  EXPECT_NEAR(vehicle.status().pose.x, 3.0, 1e-9);
  vehicle.step(seconds_to_ns(20));
  EXPECT_NEAR(vehicle.status().pose.x, 3.0, 1e-9);
  vehicle.resume();
  ASSERT_TRUE(step_until(
      vehicle, [&] { return state_of(vehicle, "m1") == CommandState::finished; }, kMs,
      seconds_to_ns(60)));
  EXPECT_NEAR(ns_to_seconds(vehicle.now()), 25 + test::trapezoid_time(2, 1, 0.5, 0.5), 0.0011);
}

TEST(SimPause, PausedMidTurnItTurnsNoMoreAndSaysSo) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "C");  // facing +x; cd leads to +y: it turns first
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "C", "cd", "D", 1.0)));
  vehicle.step(100 * kMs);
  ASSERT_NE(vehicle.status().angular_speed, 0);
  vehicle.pause();
  EXPECT_EQ(vehicle.status().angular_speed, 0) << "a paused vehicle reported turning";
  const double heading = vehicle.status().pose.theta;
  vehicle.step(seconds_to_ns(1));
  EXPECT_EQ(vehicle.status().angular_speed, 0);
  EXPECT_DOUBLE_EQ(vehicle.status().pose.theta, heading);
  vehicle.resume();
  ASSERT_TRUE(step_until(
      vehicle, [&] { return state_of(vehicle, "m1") == CommandState::finished; }, 10 * kMs, seconds_to_ns(60)));
  EXPECT_NEAR(vehicle.status().pose.y, 5.0, 1e-9);
}

TEST(SimCancel, RunningMoveBrakesAndEndsCancelledWithWhatFollows) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  vehicle.step(seconds_to_ns(3));
  ASSERT_TRUE(vehicle.cancel("m1"));
  EXPECT_EQ(state_of(vehicle, "m1"), CommandState::running);  // still braking
  vehicle.step(seconds_to_ns(2));
  EXPECT_EQ(state_of(vehicle, "m1"), CommandState::cancelled);
  EXPECT_EQ(state_of(vehicle, "m2"), CommandState::cancelled);
  EXPECT_NEAR(vehicle.status().pose.x, 3.0, 1e-9);
  EXPECT_EQ(vehicle.planned_end(), vehicle.status().pose);
  // Stopped part-way along ab, it can be sent on to either end of the edge.
  ASSERT_TRUE(vehicle.submit(move(*world, "back", "A", "ab", "A", 1.0)));
  ASSERT_TRUE(vehicle.submit(move(*world, "on", "A", "ab", "B", 1.0)));
  ASSERT_TRUE(step_until(
      vehicle, [&] { return state_of(vehicle, "on") == CommandState::finished; }, 10 * kMs,
      seconds_to_ns(60)));
  EXPECT_EQ(state_of(vehicle, "back"), CommandState::finished);
  EXPECT_DOUBLE_EQ(vehicle.status().pose.x, 5.0);
}

// The logical agent cancels each move it has not seen end, oldest first: a cancel of a
// later one while the vehicle brakes for the first must not stop it dead.
TEST(SimCancel, CancellingEachQueuedMoveInTurnStillBrakesAlongThePath) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  vehicle.step(seconds_to_ns(3));  // x = 2 at 1 m/s
  ASSERT_TRUE(vehicle.cancel("m1"));
  ASSERT_TRUE(vehicle.cancel("m2"));
  EXPECT_EQ(state_of(vehicle, "m1"), CommandState::running);  // still braking
  EXPECT_GT(vehicle.status().linear_speed, 0.5);
  vehicle.step(seconds_to_ns(2));
  EXPECT_EQ(state_of(vehicle, "m1"), CommandState::cancelled);
  EXPECT_EQ(state_of(vehicle, "m2"), CommandState::cancelled);
  EXPECT_NEAR(vehicle.status().pose.x, 3.0, 1e-9);  // 1 m of braking at 0.5 m/s²
}

TEST(SimCancel, QueuedMoveIsDroppedAndTheVehicleStopsBeforeIt) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  vehicle.step(seconds_to_ns(3));  // 2 m before B at 1 m/s: it can still stop at B
  ASSERT_TRUE(vehicle.cancel("m2"));
  EXPECT_EQ(state_of(vehicle, "m2"), CommandState::cancelled);
  ASSERT_TRUE(step_until(
      vehicle, [&] { return state_of(vehicle, "m1") == CommandState::finished; }, kMs,
      seconds_to_ns(60)));
  EXPECT_EQ(vehicle.status().linear_speed, 0);
  EXPECT_DOUBLE_EQ(vehicle.status().pose.x, 5.0);
  EXPECT_NEAR(ns_to_seconds(vehicle.now()), test::trapezoid_time(5, 1, 0.5, 0.5), 0.0011);
}

TEST(SimCancel, TooLateToStopBeforeTheCancelledMoveBrakesIntoIt) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  vehicle.step(seconds_to_ns(5.5));  // x = 4.5 at 1 m/s; stopping takes 1 m: past B
  ASSERT_TRUE(vehicle.cancel("m2"));
  EXPECT_EQ(state_of(vehicle, "m2"), CommandState::accepted);
  vehicle.step(seconds_to_ns(2));
  EXPECT_EQ(state_of(vehicle, "m1"), CommandState::finished);
  EXPECT_EQ(state_of(vehicle, "m2"), CommandState::cancelled);
  EXPECT_NEAR(vehicle.status().pose.x, 5.5, 1e-9);
  EXPECT_EQ(vehicle.status().linear_speed, 0);
}

TEST(SimCancel, ACommandWhileBrakingForACancelIsRefusedUntilTheVehicleStandsStill) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  vehicle.step(seconds_to_ns(3));  // 1 m/s: braking at 0.5 m/s² takes 2 s
  ASSERT_TRUE(vehicle.cancel("m1"));
  // Queued now, it would start at B (where m1 ends) and be cancelled with m1 once it stands.
  const auto early = vehicle.submit(move(*world, "early", "A", "ab", "B", 1.0));
  ASSERT_FALSE(early);
  EXPECT_EQ(early.error().code, rejection_code::kNotReady);
  EXPECT_EQ(state_of(vehicle, "early"), CommandState::rejected);
  // 1 ms before it stands its speed is 0.5 mm/s: standing still, as its status says, so the
  // cancel completes and the next command starts where the vehicle is.
  vehicle.step(seconds_to_ns(2) - kMs);
  ASSERT_TRUE(standing_still(vehicle.status().linear_speed, vehicle.status().angular_speed));
  ASSERT_GT(vehicle.status().linear_speed, 0);
  ASSERT_TRUE(vehicle.submit(move(*world, "on", "A", "ab", "B", 1.0)));
  EXPECT_EQ(state_of(vehicle, "m1"), CommandState::cancelled);
  EXPECT_EQ(state_of(vehicle, "on"), CommandState::running);  // not cancelled with m1
  ASSERT_TRUE(step_until(
      vehicle, [&] { return state_of(vehicle, "on") == CommandState::finished; }, 10 * kMs, seconds_to_ns(60)));
  EXPECT_DOUBLE_EQ(vehicle.status().pose.x, 5.0);
}

TEST(SimCancel, UnknownOrEndedCommandIsRefused) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  EXPECT_EQ(vehicle.cancel("nope").error().code, rejection_code::kUnknownCommand);
  ASSERT_TRUE(vehicle.submit(ActionCommand{"c", ActionKind::charge, "", {}}));
  vehicle.step(seconds_to_ns(1));
  EXPECT_EQ(vehicle.cancel("c").error().code, rejection_code::kUnknownCommand);
}

TEST(SimCancel, RunningActionStopsAtOnce) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(ActionCommand{"load", ActionKind::load, "", {}}));
  vehicle.step(seconds_to_ns(1));
  ASSERT_TRUE(vehicle.cancel("load"));
  EXPECT_EQ(state_of(vehicle, "load"), CommandState::cancelled);
  EXPECT_EQ(vehicle.status().load, LoadState::empty);
}

}  // namespace
}  // namespace drover::ran
