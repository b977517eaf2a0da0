// Battery accounting and actions of the simulated vehicle.

#include <gtest/gtest.h>

#include "tests/ran/sim_world.hpp"

namespace drover::ran {
namespace {

using test::move;
using test::state_of;
using test::step_until;
using test::vehicle_at;

constexpr DurationNs kMs = 1'000'000;

ActionCommand action(CommandId id, ActionKind kind, std::string name = {},
                     std::map<std::string, std::string> parameters = {}) {
  return ActionCommand{std::move(id), kind, std::move(name), std::move(parameters)};
}

bool finished(const SimVehicle& vehicle, const CommandId& id) {
  return state_of(vehicle, id) == CommandState::finished;
}

TEST(SimBattery, DrainsPerMetreDriven) {
  const auto world = test::world();
  SimVehicleConfig config;
  config.battery_initial_wh = 100;
  config.drain_wh_per_metre = 2.0;
  auto vehicle = vehicle_at(world, "A", config);
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  vehicle.step(seconds_to_ns(3));  // 1 m accelerating, then 1 m at 1 m/s
  EXPECT_NEAR(vehicle.status().battery.energy_wh, 100 - 2.0 * 2.0, 1e-9);
  ASSERT_TRUE(step_until(vehicle, [&] { return finished(vehicle, "m2"); }, 100 * kMs,
                         seconds_to_ns(60)));
  const auto status = vehicle.status();
  EXPECT_NEAR(status.battery.energy_wh, 100 - 2.0 * 10.0, 1e-9);
  EXPECT_NEAR(status.battery.state_of_charge, 80.0 / 1000.0, 1e-12);
}

TEST(SimBattery, ChargesPerSecondUpToTheTargetAndNeverAboveCapacity) {
  const auto world = test::world();
  SimVehicleConfig config;
  config.battery_capacity_wh = 100;
  config.battery_initial_wh = 40;
  config.charge_wh_per_second = 2.0;
  auto vehicle = vehicle_at(world, "A", config);
  ASSERT_TRUE(vehicle.submit(action("c1", ActionKind::charge, "", {{"target", "0.5"}})));
  vehicle.step(seconds_to_ns(2));
  EXPECT_TRUE(vehicle.status().battery.charging);
  EXPECT_NEAR(vehicle.status().battery.energy_wh, 44, 1e-9);
  ASSERT_TRUE(step_until(vehicle, [&] { return finished(vehicle, "c1"); }, 10 * kMs,
                         seconds_to_ns(60)));
  EXPECT_NEAR(ns_to_seconds(vehicle.now()), 5.0, 0.0101);  // 10 Wh at 2 Wh/s
  EXPECT_NEAR(vehicle.status().battery.energy_wh, 50, 1e-9);
  EXPECT_FALSE(vehicle.status().battery.charging);

  ASSERT_TRUE(vehicle.submit(action("c2", ActionKind::charge)));  // to full
  vehicle.step(seconds_to_ns(3600));
  EXPECT_EQ(state_of(vehicle, "c2"), CommandState::finished);
  EXPECT_DOUBLE_EQ(vehicle.status().battery.energy_wh, 100);
}

TEST(SimBattery, RunsEmptyWithoutGoingBelowZeroAndRecoversByCharging) {
  const auto world = test::world();
  SimVehicleConfig config;
  config.battery_initial_wh = 3;
  config.drain_wh_per_metre = 1.0;  // 3 m of range for a 5 m move
  auto vehicle = vehicle_at(world, "A", config);
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  ASSERT_TRUE(step_until(
      vehicle, [&] { return state_of(vehicle, "m1") != CommandState::running; }, 50 * kMs,
      seconds_to_ns(60)));
  auto status = vehicle.status();
  EXPECT_EQ(status.find_command("m1")->state, CommandState::failed);
  EXPECT_EQ(status.find_command("m1")->code, "battery_empty");
  EXPECT_EQ(status.find_command("m2")->state, CommandState::failed);
  EXPECT_EQ(status.find_command("m2")->code, "previous_failed");
  EXPECT_TRUE(status.has_error("battery_empty"));
  EXPECT_EQ(status.battery.energy_wh, 0);
  EXPECT_NEAR(status.pose.x, 3.0, 1e-6);  // stopped where the energy ran out
  EXPECT_EQ(status.linear_speed, 0);
  vehicle.step(seconds_to_ns(10));
  EXPECT_NEAR(vehicle.status().pose.x, 3.0, 1e-6);

  // Moves are refused while empty; charging is not.
  auto refused = vehicle.submit(move(*world, "m3", "A", "ab", "B", 1.0));
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, rejection_code::kNotReady);
  ASSERT_TRUE(vehicle.submit(action("c1", ActionKind::charge, "", {{"target", "0.01"}})));
  ASSERT_TRUE(step_until(vehicle, [&] { return finished(vehicle, "c1"); }, 100 * kMs,
                         seconds_to_ns(60)));
  EXPECT_FALSE(vehicle.status().has_error("battery_empty"));
}

TEST(SimBattery, ArrivingWithTheLastWattHourIsNoFailure) {
  const auto world = test::world();
  SimVehicleConfig config;
  config.battery_initial_wh = 5;
  config.drain_wh_per_metre = 1.0;  // exactly the 5 m to B
  auto vehicle = vehicle_at(world, "A", config);
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  ASSERT_TRUE(step_until(
      vehicle, [&] { return state_of(vehicle, "m2") != CommandState::accepted; }, 10 * kMs,
      seconds_to_ns(60)));
  const auto status = vehicle.status();
  EXPECT_EQ(status.find_command("m1")->state, CommandState::finished);
  EXPECT_EQ(status.find_command("m2")->state, CommandState::failed);
  EXPECT_EQ(status.find_command("m2")->code, "battery_empty");
  EXPECT_NEAR(status.battery.energy_wh, 0, 1e-9);
}

TEST(SimActions, LoadAndUnloadTakeTheirDurationAndChangeTheLoad) {
  const auto world = test::world();
  SimVehicleConfig config;
  config.load_duration = seconds_to_ns(4);
  config.unload_duration = seconds_to_ns(2);
  auto vehicle = vehicle_at(world, "A", config);
  EXPECT_EQ(vehicle.status().load, LoadState::empty);
  ASSERT_TRUE(vehicle.submit(action("load", ActionKind::load)));
  ASSERT_TRUE(vehicle.submit(action("unload", ActionKind::unload)));
  vehicle.step(seconds_to_ns(4) - 1);
  EXPECT_EQ(state_of(vehicle, "load"), CommandState::running);
  EXPECT_EQ(state_of(vehicle, "unload"), CommandState::accepted);
  vehicle.step(1);
  EXPECT_EQ(state_of(vehicle, "load"), CommandState::finished);
  EXPECT_EQ(vehicle.status().load, LoadState::loaded);
  vehicle.step(seconds_to_ns(2));
  EXPECT_EQ(state_of(vehicle, "unload"), CommandState::finished);
  EXPECT_EQ(vehicle.status().load, LoadState::empty);
}

TEST(SimActions, CustomActionsRunForTheirConfiguredTime) {
  const auto world = test::world();
  SimVehicleConfig config;
  config.custom_actions["beep"] = seconds_to_ns(1.5);
  auto vehicle = vehicle_at(world, "A", config);
  ASSERT_TRUE(vehicle.submit(action("b1", ActionKind::custom, "beep", {{"volume", "3"}})));
  vehicle.step(seconds_to_ns(1.4));
  EXPECT_EQ(state_of(vehicle, "b1"), CommandState::running);
  vehicle.step(seconds_to_ns(0.1));
  EXPECT_EQ(state_of(vehicle, "b1"), CommandState::finished);
}

TEST(SimActions, LoadingWhenLoadedFailsAndFailsWhatFollows) {
  const auto world = test::world();
  SimVehicleConfig config;
  config.initial_load = LoadState::loaded;
  auto vehicle = vehicle_at(world, "A", config);
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  ASSERT_TRUE(vehicle.submit(action("load", ActionKind::load)));
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  ASSERT_TRUE(step_until(vehicle, [&] { return finished(vehicle, "m1"); }, 10 * kMs,
                         seconds_to_ns(60)));
  const auto status = vehicle.status();
  EXPECT_EQ(status.find_command("load")->state, CommandState::failed);
  EXPECT_EQ(status.find_command("load")->code, "already_loaded");
  EXPECT_EQ(status.find_command("m2")->state, CommandState::failed);
  EXPECT_EQ(status.find_command("m2")->code, "previous_failed");
  // The failed move is gone: the next move starts where the vehicle stands.
  EXPECT_EQ(vehicle.planned_end(), status.pose);
  EXPECT_EQ(status.linear_speed, 0);
}

TEST(SimActions, ActionsAndMovesRunInOrder) {
  const auto world = test::world();
  SimVehicleConfig config;
  config.load_duration = seconds_to_ns(3);
  auto vehicle = vehicle_at(world, "A", config);
  ASSERT_TRUE(vehicle.submit(move(*world, "m1", "A", "ab", "B", 1.0)));
  ASSERT_TRUE(vehicle.submit(action("load", ActionKind::load)));
  ASSERT_TRUE(vehicle.submit(move(*world, "m2", "B", "bc", "C", 1.0)));
  ASSERT_TRUE(step_until(vehicle, [&] { return finished(vehicle, "m2"); }, 10 * kMs,
                         seconds_to_ns(60)));
  // Two separate 5 m moves (the load in between stops the vehicle) and the load.
  EXPECT_NEAR(ns_to_seconds(vehicle.now()), 2 * test::trapezoid_time(5, 1, 0.5, 0.5) + 3, 0.0101);
  EXPECT_EQ(vehicle.status().load, LoadState::loaded);
}

}  // namespace
}  // namespace drover::ran
