// What a commander makes of a RAN's status on the wire (agents/ran_runner/src/wire.cpp).

#include <gtest/gtest.h>

#include <boost/geometry/algorithms/area.hpp>

#include "drover/ran_runner/wire.hpp"

namespace drover::ran {
namespace {

msg::RanStatus status_with_ring(const std::vector<std::pair<double, double>>& ring) {
  msg::RanStatus wire;
  wire.vehicle_id("V1");
  wire.load("empty");
  for (const auto& [x, y] : ring) {
    msg::Point2 point;
    point.x(x);
    point.y(y);
    wire.footprint().ring().push_back(point);
  }
  return wire;
}

TEST(RanStatusWire, FootprintsOfEitherWindingOpenOrClosedReadTheSame) {
  // A 2 x 1 rectangle, counter-clockwise and open (as ROS lists outlines), then clockwise
  // and closed.
  const auto ccw = from_wire(status_with_ring({{0, 0}, {2, 0}, {2, 1}, {0, 1}}));
  const auto cw = from_wire(status_with_ring({{0, 0}, {0, 1}, {2, 1}, {2, 0}, {0, 0}}));
  ASSERT_TRUE(ccw.has_value()) << ccw.error().message;
  ASSERT_TRUE(cw.has_value()) << cw.error().message;
  EXPECT_DOUBLE_EQ(boost::geometry::area(ccw->footprint), 2.0);
  // Uncorrected, the counter-clockwise ring would have area -2, and the area of a footprint
  // outside the allocated area (the monitor's measure) would come out negative.
  EXPECT_DOUBLE_EQ(boost::geometry::area(cw->footprint), 2.0);
}

TEST(RanStatusWire, AdvertisedActionsTravelAndNoneMeansNotAdvertised) {
  auto wire = status_with_ring({{0, 0}, {2, 0}, {2, 1}, {0, 1}});
  const auto silent = from_wire(wire);
  ASSERT_TRUE(silent.has_value()) << silent.error().message;
  EXPECT_TRUE(silent->actions.empty());
  EXPECT_TRUE(silent->performs("anything")) << "a RAN that advertises nothing decides itself";
  VehicleStatus status = *silent;
  status.actions = {"load", "lift"};
  const auto back = from_wire(to_wire(status));
  ASSERT_TRUE(back.has_value()) << back.error().message;
  EXPECT_EQ(back->actions, status.actions);
  EXPECT_TRUE(back->performs("lift"));
  EXPECT_FALSE(back->performs("charge"));
}

TEST(RanStatusWire, EmptyOrSelfCrossingFootprintsAreRefusedWithTheVehicleNamed) {
  for (const auto& ring : std::vector<std::vector<std::pair<double, double>>>{
           {}, {{0, 0}, {1, 0}}, {{0, 0}, {2, 1}, {2, 0}, {0, 1}}}) {
    const auto status = from_wire(status_with_ring(ring));
    ASSERT_FALSE(status.has_value()) << ring.size() << " corners";
    EXPECT_EQ(status.error().code, ErrorCode::invalid_argument);
    EXPECT_NE(status.error().message.find("status of 'V1': the footprint is not a valid polygon"), std::string::npos)
        << status.error().message;
  }
}

}  // namespace
}  // namespace drover::ran
