// Bad commands are rejected with a code and a reason naming what is wrong; the vehicle
// keeps following its last valid command.

#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

#include "tests/ran/sim_world.hpp"

namespace drover::ran {
namespace {

using test::move;
using test::state_of;
using test::vehicle_at;

class SimRejection : public ::testing::Test {
 protected:
  void SetUp() override {
    world = test::world();
    SimVehicleConfig config;
    config.custom_actions["beep"] = seconds_to_ns(1);
    vehicle.emplace(vehicle_at(world, "A", config));
    // A valid move in progress: every rejection below must leave it running.
    ASSERT_TRUE(vehicle->submit(move(*world, "good", "A", "ab", "B", 1.0)));
    vehicle->step(seconds_to_ns(2));
  }

  /// Submits, expects a rejection with `code` whose reason mentions `mention`, and checks
  /// that the good move still runs and the vehicle still moves.
  template <class Command>
  void expect_rejected(const Command& command, const char* code, const std::string& mention) {
    const double x = vehicle->status().pose.x;
    const auto result = vehicle->submit(command);
    ASSERT_FALSE(result) << command.id;
    EXPECT_EQ(result.error().code, code) << result.error().reason;
    EXPECT_NE(result.error().reason.find(mention), std::string::npos) << result.error().reason;
    const auto status = vehicle->status();
    if (!command.id.empty() && std::string(code) != rejection_code::kDuplicateId) {
      ASSERT_NE(status.find_command(command.id), nullptr);
      EXPECT_EQ(status.find_command(command.id)->state, CommandState::rejected);
      EXPECT_EQ(status.find_command(command.id)->code, code);
    }
    EXPECT_EQ(status.find_command("good")->state, CommandState::running);
    vehicle->step(seconds_to_ns(0.1));
    EXPECT_GT(vehicle->status().pose.x, x);
  }

  std::shared_ptr<const topology::Topology> world;
  std::optional<SimVehicle> vehicle;
};

TEST_F(SimRejection, UnknownVertex) {
  auto command = move(*world, "m", "B", "bc", "C", 1.0);
  command.target_vertex = "Z";
  expect_rejected(command, rejection_code::kUnknownVertex, "'Z'");
}

TEST_F(SimRejection, UnknownEdge) {
  auto command = move(*world, "m", "B", "bc", "C", 1.0);
  command.edge = "xy";
  expect_rejected(command, rejection_code::kUnknownEdge, "'xy'");
}

TEST_F(SimRejection, EdgeThatDoesNotStartWhereTheMoveStarts) {
  // The queue ends at B; cd starts at C.
  expect_rejected(move(*world, "m", "C", "cd", "D", 1.0), rejection_code::kEdgeMismatch, "'cd'");
}

TEST_F(SimRejection, DirectedEdgeDrivenBackwards) {
  auto command = move(*world, "m", "E", "de", "D", 1.0);
  expect_rejected(command, rejection_code::kEdgeMismatch, "does not lead to");
}

TEST_F(SimRejection, TargetNotAtTheVertex) {
  auto command = move(*world, "m", "B", "bc", "C", 1.0);
  command.target.x += 0.5;
  expect_rejected(command, rejection_code::kMalformed, "vertex 'C'");
}

TEST_F(SimRejection, NegativeZeroAndNonFiniteSpeeds) {
  for (double speed : {-1.0, 0.0, std::numeric_limits<double>::quiet_NaN(),
                       std::numeric_limits<double>::infinity()}) {
    auto command = move(*world, "m" + std::to_string(vehicle->revision()), "B", "bc", "C", speed);
    expect_rejected(command, rejection_code::kInvalidSpeed, "max_speed");
  }
}

TEST_F(SimRejection, SpeedAboveTheEdgeLimit) {
  expect_rejected(move(*world, "m", "B", "bc", "C", 2.5), rejection_code::kInvalidSpeed, "'bc'");
}

TEST_F(SimRejection, MalformedFields) {
  auto no_id = move(*world, "", "B", "bc", "C", 1.0);
  expect_rejected(no_id, rejection_code::kMalformed, "id");
  auto no_area = move(*world, "m1", "B", "bc", "C", 1.0);
  no_area.area.clear();
  expect_rejected(no_area, rejection_code::kMalformed, "area");
  auto nan_target = move(*world, "m2", "B", "bc", "C", 1.0);
  nan_target.target.y = std::nan("");
  expect_rejected(nan_target, rejection_code::kMalformed, "target");
  auto degenerate = move(*world, "m3", "B", "bc", "C", 1.0);
  degenerate.area = MotionArea{topology::Polygon{{{0, 0}, {1, 1}, {2, 2}, {0, 0}}}};
  expect_rejected(degenerate, rejection_code::kMalformed, "valid polygon");
}

TEST_F(SimRejection, PathLeavingTheMotionArea) {
  // Only the two vertices, not the edge between them.
  auto command = move(*world, "m", "B", "bc", "C", 1.0);
  command.area = test::area_of(*world, {"B", "C"});
  expect_rejected(command, rejection_code::kOutsideArea, "driving from");
}

TEST_F(SimRejection, TurnLeavingTheMotionArea) {
  // A vehicle 1.6 m long cannot turn inside a 1 m vertex square... but it cannot stand in
  // one either, so give it room to stand facing +x and no room to turn.
  auto command = move(*world, "m", "B", "bc", "C", 1.0, std::numbers::pi / 2);
  topology::Polygon narrow{{{4.6, -0.25}, {4.6, 0.25}, {10.5, 0.25}, {10.5, -0.25}, {4.6, -0.25}}};
  command.area = MotionArea{narrow};
  expect_rejected(command, rejection_code::kOutsideArea, "turning");
}

TEST_F(SimRejection, TheStatusAdvertisesTheActionsTheVehiclePerforms) {
  const auto status = vehicle->status();
  EXPECT_EQ(status.actions, (std::vector<std::string>{"load", "unload", "charge", "beep"}));
  EXPECT_TRUE(status.performs("beep"));
  EXPECT_FALSE(status.performs("dance"));
}

TEST_F(SimRejection, UnsupportedActionAndBadParameter) {
  expect_rejected(ActionCommand{"a1", ActionKind::custom, "dance", {}},
                  rejection_code::kUnsupportedAction, "'dance'");
  expect_rejected(ActionCommand{"a2", ActionKind::custom, "", {}}, rejection_code::kMalformed,
                  "name");
  expect_rejected(ActionCommand{"a3", ActionKind::charge, "", {{"target", "1.5"}}},
                  rejection_code::kInvalidParameter, "target");
  expect_rejected(ActionCommand{"a4", ActionKind::charge, "", {{"target", "full"}}},
                  rejection_code::kInvalidParameter, "'full'");
}

TEST_F(SimRejection, DuplicateIdIsRefusedWithoutTouchingTheOriginal) {
  expect_rejected(move(*world, "good", "B", "bc", "C", 1.0), rejection_code::kDuplicateId,
                  "'good'");
  EXPECT_EQ(vehicle->status().commands.size(), 1u);
}

TEST(SimVehicleCreate, RejectsBadConfiguration) {
  SimVehicleConfig config;
  config.deceleration = -1;
  auto created = SimVehicle::create(config, Pose{}, 0);
  ASSERT_FALSE(created);
  EXPECT_NE(created.error().message.find("deceleration"), std::string::npos);
  config = {};
  config.footprint = topology::Polygon{};
  EXPECT_FALSE(SimVehicle::create(config, Pose{}, 0));
  config = {};
  config.battery_initial_wh = config.battery_capacity_wh + 1;
  EXPECT_FALSE(SimVehicle::create(config, Pose{}, 0));
  EXPECT_FALSE(SimVehicle::create({}, Pose{std::nan(""), 0, 0}, 0));
}

TEST(SimVehicleCreate, WithoutTopologyTrustsTheCommandedPoses) {
  auto vehicle = SimVehicle::create({}, Pose{0, 0, 0}, 0).value();
  MoveCommand command;
  command.id = "free";
  command.target_vertex = "anywhere";
  command.target = {3, 0, std::nullopt};
  command.max_speed = 1;
  command.area = MotionArea{topology::Polygon{{{-1, -1}, {-1, 1}, {4, 1}, {4, -1}, {-1, -1}}}};
  ASSERT_TRUE(vehicle.submit(command));
  vehicle.step(seconds_to_ns(60));
  EXPECT_EQ(state_of(vehicle, "free"), CommandState::finished);
  EXPECT_DOUBLE_EQ(vehicle.status().pose.x, 3);
}

}  // namespace
}  // namespace drover::ran
