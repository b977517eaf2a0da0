// The simulated vehicle's motion: arrival times, speed and acceleration limits, turns,
// runs over consecutive moves, independence from the step size, staying in the area.

#include <cmath>
#include <map>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "drover/ran/motion_area.hpp"
#include "tests/ran/sim_world.hpp"

namespace drover::ran {
namespace {

using test::move;
using test::state_of;
using test::step_until;
using test::vehicle_at;

constexpr DurationNs kMs = 1'000'000;

/// Steps in 1 ms steps until the command finished; returns the time in seconds.
double finish_time(SimVehicle& vehicle, const CommandId& id) {
  const bool done = step_until(
      vehicle, [&] { return state_of(vehicle, id) == CommandState::finished; }, kMs,
      seconds_to_ns(120));
  EXPECT_TRUE(done) << id << " never finished";
  return ns_to_seconds(vehicle.now());
}

TEST(SimMotion, ReachesTheTargetInTrapezoidTime) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  EXPECT_EQ(state_of(vehicle, "m1"), CommandState::running);
  const double expected = test::trapezoid_time(5.0, 1.0, 0.5, 0.5);  // 7 s
  EXPECT_NEAR(finish_time(vehicle, "m1"), expected, 0.0011);
  const auto status = vehicle.status();
  EXPECT_DOUBLE_EQ(status.pose.x, 5.0);
  EXPECT_DOUBLE_EQ(status.pose.y, 0.0);
  EXPECT_EQ(status.linear_speed, 0.0);
}

// After a cancel a vehicle brakes to a stop where it is, often a little past the vertex it
// was nearing, on the next edge. Its commander takes it to stand on that vertex (inside its
// footprint) and sends the next route's first move from there, over any edge: the vehicle
// takes it and drives to the target inside the motion area (before, it refused the move as
// starting off the edge, and every later route failed the same way).
TEST(SimMotion, StartsAMoveFromAVertexItStoppedALittlePast) {
  const auto world = test::world();
  // Came from C westwards, stopped 0.1 m past B, on ab.
  auto created = SimVehicle::create({}, Pose{4.9, 0, std::numbers::pi}, 0, world);
  ASSERT_TRUE(created.has_value()) << created.error().message;
  auto vehicle = std::move(*created);
  const auto taken = vehicle.submit(move(*world, "m1", "B", "bc", "C", 1.0));
  ASSERT_TRUE(taken) << taken.error().reason;
  finish_time(vehicle, "m1");
  EXPECT_DOUBLE_EQ(vehicle.status().pose.x, 10.0);
  EXPECT_DOUBLE_EQ(vehicle.status().pose.y, 0.0);
  // 0.3 m past B, turning there would sweep out of B's footprint (the motion area holds B,
  // bc and C): that is still refused.
  auto further = SimVehicle::create({}, Pose{4.7, 0, std::numbers::pi}, 0, world);
  ASSERT_TRUE(further.has_value());
  const auto refused = further->submit(move(*world, "m1", "B", "bc", "C", 1.0));
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, rejection_code::kOutsideArea);
}

TEST(SimMotion, UsesTheLowerOfCommandAndVehicleSpeed) {
  const auto world = test::world();
  SimVehicleConfig config;
  config.max_speed = 0.8;
  auto vehicle = vehicle_at(world, "A", config);
  ASSERT_TRUE(vehicle.submit(move(*world, "fast", "A", "ab", "B", 2.0)));
  EXPECT_NEAR(finish_time(vehicle, "fast"), test::trapezoid_time(5.0, 0.8, 0.5, 0.5), 0.0011);
}

TEST(SimMotion, TurnsOnTheSpotBeforeDrivingAndToTheTargetHeading) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "C");  // facing +x; D is at +y
  ASSERT_TRUE(vehicle.submit(move(*world, "up", "C", "cd", "D", 1.0, std::numbers::pi)));
  const double turns = (std::numbers::pi / 2) / 1.0 * 2;  // +90 deg, then +90 deg at D
  EXPECT_NEAR(finish_time(vehicle, "up"), turns + test::trapezoid_time(5.0, 1.0, 0.5, 0.5), 0.0011);
  EXPECT_NEAR(vehicle.status().pose.theta, std::numbers::pi, 1e-9);
}

TEST(SimMotion, DrivesCollinearMovesAsOneRunWithoutStopping) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  double speed_when_m1_finished = -1;
  step_until(
      vehicle, [&] { return state_of(vehicle, "m1") == CommandState::finished; }, kMs,
      seconds_to_ns(60));
  speed_when_m1_finished = vehicle.status().linear_speed;
  EXPECT_NEAR(speed_when_m1_finished, 1.0, 1e-6);
  EXPECT_EQ(state_of(vehicle, "m2"), CommandState::running);
  EXPECT_NEAR(finish_time(vehicle, "m2"), test::trapezoid_time(10.0, 1.0, 0.5, 0.5), 0.0011);
}

TEST(SimMotion, ExtendsTheRunWhenTheNextMoveArrivesInTime) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "A");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  vehicle.step(seconds_to_ns(3));  // cruising, 2 m before B: not braking yet
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  EXPECT_NEAR(finish_time(vehicle, "m2"), test::trapezoid_time(10.0, 1.0, 0.5, 0.5), 0.0011);
}

TEST(SimMotion, StopsAtACornerAndTurns) {
  const auto world = test::world();
  auto vehicle = vehicle_at(world, "B");
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "B", "bc", "C", 1.0)));
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "C", "cd", "D", 1.0)));
  const double leg = test::trapezoid_time(5.0, 1.0, 0.5, 0.5);
  EXPECT_NEAR(finish_time(vehicle, "m1"), leg, 0.0011);
  EXPECT_EQ(vehicle.status().linear_speed, 0.0);
  EXPECT_NEAR(finish_time(vehicle, "m2"), 2 * leg + std::numbers::pi / 2, 0.0021);
}

TEST(SimMotion, ResultDoesNotDependOnTheStepSize) {
  const auto world = test::world();
  auto fine = vehicle_at(world, "A");
  auto coarse = vehicle_at(world, "A");
  for (SimVehicle* vehicle : {&fine, &coarse}) {
    ASSERT_TRUE(vehicle->submit(move(*world, "m1", "A", "ab", "B", 1.0)));
    ASSERT_TRUE(vehicle->submit(move(*world, "m2", "B", "bc", "C", 0.6)));
    ASSERT_TRUE(vehicle->submit(move(*world, "m3", "C", "cd", "D", 1.0)));
  }
  for (int i = 0; i < 7000; ++i) fine.step(3 * kMs);
  for (int i = 0; i < 21; ++i) coarse.step(1000 * kMs);
  const auto a = fine.status(), b = coarse.status();
  EXPECT_NEAR(a.pose.x, b.pose.x, 1e-6);
  EXPECT_NEAR(a.pose.y, b.pose.y, 1e-6);
  EXPECT_NEAR(a.pose.theta, b.pose.theta, 1e-9);
  EXPECT_NEAR(a.linear_speed, b.linear_speed, 1e-6);
  EXPECT_NEAR(a.battery.energy_wh, b.battery.energy_wh, 1e-6);
}

TEST(SimMotion, RandomTripsNeverExceedLimitsOrLeaveTheArea) {
  // Random walks over the world's edges with random speeds, stepped in 10 ms steps: every
  // step the distance moved respects the command's speed limit, the speed change respects
  // acceleration and deceleration, and the footprint stays inside the executing move's
  // motion area.
  const auto world = test::world();
  std::mt19937 random(11);
  std::uniform_real_distribution<double> speed(0.2, 2.0);
  struct Leg { const char* from; const char* edge; const char* to; };
  const Leg legs[] = {{"A", "ab", "B"}, {"B", "bc", "C"}, {"C", "cd", "D"},
                      {"D", "cd", "C"}, {"C", "bc", "B"}, {"B", "ab", "A"}};
  for (int round = 0; round < 6; ++round) {
    SimVehicleConfig config;
    config.acceleration = 0.3 + round * 0.2;
    config.deceleration = 0.4 + round * 0.15;
    config.max_speed = 1.6;
    auto vehicle = vehicle_at(world, "A", config);
    std::map<CommandId, double> limit;
    for (int i = 0; i < 12; ++i) {
      const Leg& leg = legs[i % 6];
      const double max_speed = speed(random);
      const auto id = "r" + std::to_string(round) + "-" + std::to_string(i);
      ASSERT_TRUE(vehicle.submit(move(*world, id, leg.from, leg.edge, leg.to, max_speed)));
      limit[id] = std::min(max_speed, config.max_speed);
    }
    const CommandId last = "r" + std::to_string(round) + "-11";
    auto before = vehicle.status();
    const DurationNs dt = 10 * kMs;
    const bool done = step_until(
        vehicle, [&] { return state_of(vehicle, last) == CommandState::finished; },
        dt, seconds_to_ns(600), [&] {
          const auto now = vehicle.status();
          const double moved = std::hypot(now.pose.x - before.pose.x, now.pose.y - before.pose.y);
          // The command running at the end of the step (or the one that just finished,
          // when the step crossed a vertex) bounds the speed.
          double bound = 0;
          for (const auto& command : before.commands) {
            if (command.state == CommandState::running) bound = std::max(bound, limit[command.id]);
          }
          for (const auto& command : now.commands) {
            if (command.state == CommandState::running) bound = std::max(bound, limit[command.id]);
          }
          EXPECT_LE(moved, bound * ns_to_seconds(dt) + 1e-9);
          EXPECT_LE(now.linear_speed, bound + 1e-9);
          EXPECT_LE(now.linear_speed - before.linear_speed,
                    config.acceleration * ns_to_seconds(dt) + 1e-9);
          EXPECT_LE(before.linear_speed - now.linear_speed,
                    config.deceleration * ns_to_seconds(dt) + 1e-9);
          if (const MotionArea* area = vehicle.active_area()) {
            EXPECT_LE(area_outside(now.footprint, *area), 1e-9)
                << "outside the area at (" << now.pose.x << ", " << now.pose.y << ")";
          }
          before = now;
        });
    EXPECT_TRUE(done);
  }
}

}  // namespace
}  // namespace drover::ran
