// The planner at the edges of its ranges: times near kForever, vehicles too slow for the
// graph, more stops or longer dwells than it takes, the horizon's cut, and timelines that
// cover only part of the topology. Each answer is a clear error or a valid route, never an
// overflowed time (the sanitized stage of the test command runs these under UBSan).

#include <gtest/gtest.h>

#include "drover/carp/free_path.hpp"
#include "drover/carp/planner.hpp"
#include "drover/topology/footprints.hpp"
#include "drover/topology/topology_builder.hpp"
#include "grid_builder.hpp"
#include "route_checks.hpp"

namespace drover::carp::test {
namespace {

Stop open_stop(const World& w, const std::string& id) { return Stop{w.at(id), std::nullopt}; }

PlanError plan_error(World& w, const PlanRequest& request) {
  auto planned = w.planner.plan(w.timelines, request);
  EXPECT_FALSE(planned.has_value()) << "arrival " << (planned ? planned->arrival : 0);
  return planned ? PlanError{} : planned.error();
}

bool mentions(const PlanError& error, const std::string& text) {
  return error.message.find(text) != std::string::npos;
}

// A window that opens less than one travel time before kForever: the arrival through it
// must not wrap around to a negative time (it used to give a route arriving before it
// started, or a search that never ended).
TEST(PlannerLimits, WindowsOpeningNearForeverAreBeyondTheHorizon) {
  World w(GridBuilder().corridor(3, EdgeOptions{.length = 2.0}).build());
  w.occupy("b", "1,0", 0, kForever - sec(1.5));
  for (const char* goal : {"1,0", "2,0"}) {
    const PlanError error = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, goal)}));
    EXPECT_EQ(error.reason, PlanFailure::no_window) << goal << ": " << error.message;
  }
  // The same on an edge alone: its footprint keeps clear of its vertices, so only its own
  // timeline opens late.
  topology::TopologyBuilder builder("apart");
  for (const double x : {0.0, 10.0}) {
    topology::VertexSpec vertex;
    vertex.id = x == 0 ? "a" : "b";
    vertex.x = x;
    vertex.footprint = topology::axis_aligned_rectangle(x - 0.5, -0.5, x + 0.5, 0.5);
    builder.add_vertex(std::move(vertex));
  }
  topology::EdgeSpec between;
  between.id = "a-b";
  between.from = "a";
  between.to = "b";
  between.length = 2.0;
  between.footprint = topology::axis_aligned_rectangle(3, -0.5, 7, 0.5);
  builder.add_edge(std::move(between));
  auto built = std::move(builder).build();
  ASSERT_TRUE(built.has_value());
  World edge(std::move(built).value());
  edge.occupy("other", "a-b", 0, kForever - sec(1.5));
  const PlanError error = plan_error(edge, request_to(edge, "a", "a", {open_stop(edge, "b")}));
  // (Said as "for good": the only way in opens too late for any arrival to be a time.)
  EXPECT_EQ(error.reason, PlanFailure::no_window) << error.message;
}

// The same with a last stop held for a while: whether it can be held there is decided
// without adding the dwell to a start near kForever.
TEST(PlannerLimits, AHoldNearForeverIsBeyondTheHorizon) {
  World w(GridBuilder().corridor(3).build());
  w.occupy("b", "2,0", 0, kForever - sec(1.5));
  const PlanError error =
      plan_error(w, request_to(w, "a", "0,0", {Stop{w.at("2,0"), sec(10)}}));
  EXPECT_EQ(error.reason, PlanFailure::no_window) << error.message;
  // Without the reservation the same request is planned.
  World empty(GridBuilder().corridor(3).build());
  const auto held = empty.planner.plan(
      empty.timelines, request_to(empty, "a", "0,0", {Stop{empty.at("2,0"), sec(10)}}));
  EXPECT_TRUE(held.has_value()) << held.error().message;
}

// A floor proof that raises the floor past the deadline ends the search, cut by the
// horizon (proofs after every floor-keyed expansion, so that one runs at once).
TEST(PlannerLimits, AFloorRaisedPastTheDeadlineEndsTheSearch) {
  World w(GridBuilder().corridor(4).build(),
          PlannerOptions{.horizon = sec(10), .quick_proof_after = 1, .floor_proof_after = 1});
  w.occupy("b", "3,0", 0, sec(5));   // the goal is free for good from 5 s: the first floor
  w.occupy("c", "1,0", 0, sec(20));  // but the way there opens only at 20 s
  const PlanError error = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "3,0")}));
  EXPECT_EQ(error.reason, PlanFailure::no_window) << error.message;
  EXPECT_TRUE(mentions(error, "within the horizon of 10.000 s")) << error.message;
  EXPECT_GT(w.planner.last_stats().arrival_floor, sec(10));
  EXPECT_GE(w.planner.last_stats().floor_proofs, 1u);
}

TEST(PlannerLimits, AVehicleTooSlowForTheGraphIsRefusedNotPlannedAtTopSpeed) {
  World w(GridBuilder().corridor(3).build());
  // Out of the profile's physical bounds: refused before any search.
  PlanRequest snail = request_to(w, "a", "0,0", {open_stop(w, "2,0")});
  snail.vehicle.max_speed = 1e-12;  // a metre in 30 000 years
  snail.vehicle.id = "snail";
  const PlanError out_of_bounds = plan_error(w, snail);
  EXPECT_EQ(out_of_bounds.reason, PlanFailure::invalid_request) << out_of_bounds.message;
  EXPECT_TRUE(mentions(out_of_bounds, "vehicle 'snail': max_speed must be from 0.001 to 100 m/s"))
      << out_of_bounds.message;
  PlanRequest long_vehicle = request_to(w, "a", "0,0", {open_stop(w, "2,0")});
  long_vehicle.vehicle.length = 1e12;
  EXPECT_EQ(plan_error(w, long_vehicle).reason, PlanFailure::invalid_request);

  // Within bounds, but an edge's crawling speed limit makes the vehicle too slow for it.
  World crawl(GridBuilder().corridor(3).cell(0, 1).edge(0, 0, 0, 1, EdgeOptions{.max_speed = 1e-12}).build());
  PlanRequest slow = request_to(crawl, "a", "0,0", {open_stop(crawl, "2,0")});
  slow.vehicle.id = "snail";
  const PlanError error = plan_error(crawl, slow);
  EXPECT_EQ(error.reason, PlanFailure::invalid_request) << error.message;
  EXPECT_TRUE(mentions(error, "vehicle 'snail' is too slow")) << error.message;
  // Another vehicle of the same class (the traversal is shared) is named as itself.
  slow.vehicle.id = "slug";
  EXPECT_TRUE(mentions(plan_error(crawl, slow), "vehicle 'slug' is too slow"));

  FreePathSearch free(crawl.graph);
  const auto path = free.find(slow.vehicle, crawl.at("0,0"), crawl.at("2,0"));
  ASSERT_FALSE(path.has_value());
  EXPECT_EQ(path.error().code, ErrorCode::invalid_argument) << path.error().message;

  // An arc it may not drive does not count: a crawling speed limit on an edge kept for
  // another vehicle type.
  topology::Restrictions forklifts_only;
  forklifts_only.allowed_vehicle_types = {"forklift"};
  World restricted(
      GridBuilder()
          .corridor(3)
          .cell(0, 1)
          .edge(0, 0, 0, 1, EdgeOptions{.max_speed = 1e-12, .restrictions = forklifts_only})
          .build());
  auto unhindered = restricted.planner.plan(
      restricted.timelines, request_to(restricted, "a", "0,0", {open_stop(restricted, "2,0")}));
  EXPECT_TRUE(unhindered.has_value()) << unhindered.error().message;

  // Slow but within range: planned, at its speed.
  PlanRequest crawling = request_to(w, "a", "0,0", {open_stop(w, "2,0")});
  crawling.vehicle.max_speed = 1e-3;
  auto planned = w.planner.plan(w.timelines, crawling);
  ASSERT_TRUE(planned.has_value()) << planned.error().message;
  EXPECT_EQ(planned->arrival, sec(2000));
}

TEST(PlannerLimits, MoreStopsThanOneRequestMayHaveAreRefused) {
  World w(GridBuilder().corridor(3).build());
  std::vector<Stop> stops(kMaxStops, Stop{w.at("0,0"), std::nullopt});
  auto most = w.planner.plan(w.timelines, request_to(w, "a", "0,0", stops));
  ASSERT_TRUE(most.has_value()) << most.error().message;
  EXPECT_EQ(most->stop_arrivals.size(), kMaxStops);

  stops.push_back(Stop{w.at("0,0"), std::nullopt});
  const PlanError error = plan_error(w, request_to(w, "a", "0,0", stops));
  EXPECT_EQ(error.reason, PlanFailure::invalid_request) << error.message;
  EXPECT_TRUE(mentions(error, std::to_string(kMaxStops + 1) + " stops")) << error.message;
}

TEST(PlannerLimits, DwellsAddingUpPastTheLongestDurationAreRefused) {
  World w(GridBuilder().corridor(3).build(), PlannerOptions{.horizon = kForever});
  const DurationNs half = kLongestDuration / 2;
  std::vector<Stop> stops{{w.at("2,0"), half}, {w.at("1,0"), half}, {w.at("2,0"), half},
                          {w.at("0,0"), std::nullopt}};
  const PlanError error = plan_error(w, request_to(w, "a", "0,0", stops));
  EXPECT_EQ(error.reason, PlanFailure::invalid_request) << error.message;
  EXPECT_TRUE(mentions(error, "dwells of stops 0 to 2")) << error.message;
}

// A horizon longer than kLongestDuration counts as kLongestDuration, and says so; stops
// that cannot fit into it even on an empty map fail before any search.
TEST(PlannerLimits, TheHorizonReportedIsTheOneApplied) {
  World w(GridBuilder().corridor(3).build(), PlannerOptions{.horizon = kForever});
  const std::vector<Stop> stops{{w.at("2,0"), kLongestDuration}, {w.at("0,0"), std::nullopt}};
  const PlanError error = plan_error(w, request_to(w, "a", "0,0", stops));
  EXPECT_EQ(error.reason, PlanFailure::no_window) << error.message;
  EXPECT_TRUE(mentions(error, "even on an empty topology")) << error.message;
  EXPECT_FALSE(mentions(error, "forever")) << error.message;

  // Here the search itself runs into the horizon: the way is blocked until after it.
  World short_horizon(GridBuilder().corridor(3).build(), PlannerOptions{.horizon = sec(2.5)});
  short_horizon.occupy("b", "1,0", 0, sec(10));
  const PlanError too_far = plan_error(
      short_horizon, request_to(short_horizon, "a", "0,0", {open_stop(short_horizon, "2,0")}));
  EXPECT_EQ(too_far.reason, PlanFailure::no_window) << too_far.message;
  EXPECT_TRUE(mentions(too_far, "within the horizon of 2.500 s")) << too_far.message;
}

// A plant's shared clock reads Unix time: routes start until 2116 (kLatestTime), with the
// longest horizon and dwells on top and no sum overflowing (UBSan in the sanitized stage).
TEST(PlannerLimits, RoutesStartUntilTheLatestTimeWithTheLongestDurationsOnTop) {
  World w(GridBuilder().corridor(3).build(), PlannerOptions{.horizon = kForever});
  const TimeNs year_2100 = 4'102'444'800 * kNsPerSecond;  // 2100-01-01T00:00:00Z
  for (const TimeNs start : {year_2100, kLatestTime}) {
    SCOPED_TRACE(start);
    const auto planned = w.planner.plan(
        w.timelines, request_to(w, "a", "0,0",
                                {{w.at("2,0"), kLongestDuration / 2}, {w.at("0,0"), kLongestDuration / 2}},
                                start));
    ASSERT_TRUE(planned.has_value()) << planned.error().message;
    EXPECT_EQ(planned->steps.front().window.start, start);
    EXPECT_EQ(planned->stop_arrivals[0], start + sec(2));
    EXPECT_EQ(planned->arrival, start + sec(4) + kLongestDuration / 2);
  }
  const PlanError late = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "2,0")}, kLatestTime + 1));
  EXPECT_EQ(late.reason, PlanFailure::invalid_request) << late.message;
  EXPECT_TRUE(mentions(late, "out of range (0 to " + std::to_string(kLatestTime) + " ns)")) << late.message;
}

// A set owning part of the topology sees the rest as another's: the planner would blame a
// phantom agent for every failure, so it refuses such timelines.
TEST(PlannerLimits, TimelinesOfPartOfTheTopologyAreRefused) {
  World w(GridBuilder().corridor(3).build());
  std::vector<bool> owned(w.topology.entity_count(), true);
  owned[w.at("2,0")] = false;
  const topology::TimelineSet part(w.topology.conflict_sets(), owned);
  auto planned = w.planner.plan(part, request_to(w, "a", "0,0", {open_stop(w, "1,0")}));
  ASSERT_FALSE(planned.has_value());
  EXPECT_EQ(planned.error().reason, PlanFailure::invalid_request) << planned.error().message;
  EXPECT_TRUE(mentions(planned.error(), "only part")) << planned.error().message;
}

}  // namespace
}  // namespace drover::carp::test
