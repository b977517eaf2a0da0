// Unit tests of the CARP planner: timing model, waiting, speeds, restrictions, locks,
// stops and dwells, errors, test and real routes.

#include <gtest/gtest.h>

#include "drover/carp/planner.hpp"
#include "grid_builder.hpp"
#include "route_checks.hpp"

namespace drover::carp::test {
namespace {

using topology::Interval;
using topology::RouteStep;

Stop open_stop(const World& w, const std::string& id) { return Stop{w.at(id), std::nullopt}; }
Stop dwell_stop(const World& w, const std::string& id, double seconds) {
  return Stop{w.at(id), sec(seconds)};
}

Route plan_ok(World& w, const PlanRequest& request) {
  auto planned = w.planner.plan(w.timelines, request);
  EXPECT_TRUE(planned.has_value()) << (planned ? "" : planned.error().message);
  if (!planned) return {};
  check_route(w.topology, w.timelines, request, *planned);
  return *planned;
}

PlanError plan_error(World& w, const PlanRequest& request) {
  auto planned = w.planner.plan(w.timelines, request);
  EXPECT_FALSE(planned.has_value());
  if (planned) return {};
  EXPECT_FALSE(planned.error().message.empty());
  return planned.error();
}

TEST(Planner, EmptyCorridorWindowsOverlapByTheClearanceTime) {
  World w(GridBuilder().corridor(5).build());
  const Route route = plan_ok(w, request_to(w, "a", "0,0", {open_stop(w, "4,0")}));
  const std::vector<RouteStep> expected{
      {w.at("0,0"), {sec(0), sec(1)}},     {w.at("0,0-1,0"), {sec(0), sec(2)}},
      {w.at("1,0"), {sec(1), sec(2)}},     {w.at("1,0-2,0"), {sec(1), sec(3)}},
      {w.at("2,0"), {sec(2), sec(3)}},     {w.at("2,0-3,0"), {sec(2), sec(4)}},
      {w.at("3,0"), {sec(3), sec(4)}},     {w.at("3,0-4,0"), {sec(3), sec(5)}},
      {w.at("4,0"), {sec(4), kForever}},
  };
  EXPECT_EQ(route.steps, expected);
  EXPECT_EQ(route.arrival, sec(4));
  EXPECT_EQ(route.travel_time, sec(4));
  EXPECT_DOUBLE_EQ(route.distance, 4.0);
}

TEST(Planner, StartTimeShiftsEverything) {
  World w(GridBuilder().corridor(3).build());
  const Route route = plan_ok(w, request_to(w, "a", "2,0", {open_stop(w, "0,0")}, sec(100)));
  EXPECT_EQ(route.arrival, sec(102));
  EXPECT_EQ(route.travel_time, sec(2));
}

TEST(Planner, WaitsUntilAnotherAgentsReservationIsOver) {
  World w(GridBuilder().corridor(5).build());
  w.occupy("b", "2,0", sec(0), sec(5));
  const Route route = plan_ok(w, request_to(w, "a", "0,0", {open_stop(w, "4,0")}));
  // 2,0 and the edges touching it are free from 5 s on: 2,0 at 6 s at the earliest
  // (the edge into it is held 1 s before), then two more cells.
  EXPECT_EQ(route.arrival, sec(8));
}

TEST(Planner, ArrivesOneMoveAfterTheGoalIsFreeWhenTheEdgesInAreBlockedAsLong) {
  // The goal is free from 5 s on, and so is the edge into it (which conflicts with it):
  // the arrival floor looks one step back and starts the search at 6 s, the true arrival.
  World w(GridBuilder().corridor(3).build());
  w.occupy("b", "2,0", sec(0), sec(5));
  const Route route = plan_ok(w, request_to(w, "a", "0,0", {open_stop(w, "2,0")}));
  EXPECT_EQ(route.arrival, sec(6));
  // A last leg that starts on its stop needs no arc: arriving there at the start time.
  w.occupy("c", "0,0", sec(0), sec(1));
  const Route stay = plan_ok(w, request_to(w, "a", "1,0", {open_stop(w, "1,0")}));
  EXPECT_EQ(stay.arrival, sec(0));
}

TEST(Planner, TheAgentsOwnReservationsNeverBlockIt) {
  World w(GridBuilder().corridor(5).build());
  w.occupy("a", "2,0", sec(0), sec(50));
  const Route route = plan_ok(w, request_to(w, "a", "0,0", {open_stop(w, "4,0")}));
  EXPECT_EQ(route.arrival, sec(4));
}

TEST(Planner, TakesTheFasterDetourWhenWaitingIsSlower) {
  // Two rows of five cells joined at both ends: straight along y = 0 (4 cells) or round
  // through y = 1 (6 cells). Blocking the straight way for 10 s makes the detour faster.
  GridBuilder g;
  for (int x = 0; x < 5; ++x) g.cell(x, 0).cell(x, 1);
  for (int x = 0; x + 1 < 5; ++x) g.edge(x, 0, x + 1, 0).edge(x, 1, x + 1, 1);
  g.edge(0, 0, 0, 1).edge(4, 0, 4, 1);
  World w(std::move(g).build());
  w.occupy("b", "2,0", sec(0), sec(10));
  const Route route = plan_ok(w, request_to(w, "a", "0,0", {open_stop(w, "4,0")}));
  EXPECT_EQ(route.arrival, sec(6));
  for (const auto& step : route.steps) EXPECT_NE(step.entity, w.at("2,0"));
}

TEST(Planner, DrivesEachEdgeAtTheLowestApplicableSpeed) {
  GridBuilder g;
  g.cell(0, 0).cell(1, 0).cell(2, 0);
  topology::Restrictions slow_vertex;
  slow_vertex.max_speed = 0.25;
  g.cell(3, 0, slow_vertex);
  topology::Restrictions slow_edge;
  slow_edge.max_speed = 0.5;
  g.edge(0, 0, 1, 0, {.length = 2, .max_speed = 4})                // vehicle: 2 m/s -> 1 s
      .edge(1, 0, 2, 0, {.length = 1, .max_speed = 4, .restrictions = slow_edge})  // 2 s
      .edge(2, 0, 3, 0, {.length = 1, .max_speed = 4});  // vertex limit 0.25 -> 4 s
  World w(std::move(g).build());
  PlanRequest request = request_to(w, "a", "0,0", {open_stop(w, "3,0")});
  request.vehicle.max_speed = 2;
  const Route route = plan_ok(w, request);
  EXPECT_EQ(route.arrival, sec(7));
  // The clearance follows the speed too: 1 m at 0.25 m/s spans 4 s.
  EXPECT_EQ(route.steps[4].window, (Interval{sec(3), sec(3) + sec(4)}));
}

TEST(Planner, RestrictionsForceADetour) {
  GridBuilder g;
  for (int x = 0; x < 3; ++x) g.cell(x, 0).cell(x, 1);
  topology::Restrictions no_agv;
  no_agv.forbidden_vehicle_types = {"agv"};
  g.edge(0, 0, 1, 0).edge(1, 0, 2, 0, {.restrictions = no_agv}).edge(0, 1, 1, 1).edge(1, 1, 2, 1);
  g.edge(0, 0, 0, 1).edge(1, 0, 1, 1).edge(2, 0, 2, 1);
  World w(std::move(g).build());
  const Route route = plan_ok(w, request_to(w, "a", "0,0", {open_stop(w, "2,0")}));
  for (const auto& step : route.steps) EXPECT_NE(step.entity, w.at("1,0-2,0"));
  EXPECT_EQ(route.arrival, sec(4));

  PlanRequest forklift = request_to(w, "f", "0,0", {open_stop(w, "2,0")});
  forklift.vehicle.type = "forklift";
  EXPECT_EQ(plan_ok(w, forklift).arrival, sec(2));
}

TEST(Planner, ReportsRestrictedWhenNoUsablePathOrStopExists) {
  struct Case {
    const char* name;
    topology::Restrictions on_edge;
    topology::Restrictions on_goal;
  };
  topology::Restrictions only_people;
  only_people.allowed_vehicle_types = {"person"};
  topology::Restrictions light;
  light.max_payload = 100;
  topology::Restrictions short_only;
  short_only.max_vehicle_length = 0.5;
  topology::Restrictions narrow;
  narrow.max_vehicle_width = 0.8;
  const Case cases[] = {{"type on edge", only_people, {}},
                        {"payload on edge", light, {}},
                        {"length on goal", {}, short_only},
                        {"width on goal", {}, narrow}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    GridBuilder g;
    g.cell(0, 0).cell(1, 0).cell(2, 0, c.on_goal);
    g.edge(0, 0, 1, 0).edge(1, 0, 2, 0, {.restrictions = c.on_edge});
    World w(std::move(g).build());
    PlanRequest request = request_to(w, "a", "0,0", {open_stop(w, "2,0")});
    request.vehicle.payload = 250;
    EXPECT_EQ(plan_error(w, request).reason, PlanFailure::restricted);
  }
}

TEST(Planner, ReportsUnreachableForDisconnectedOrOneWayGraphs) {
  GridBuilder g;
  g.cell(0, 0).cell(1, 0).cell(2, 0).cell(5, 5);
  g.edge(1, 0, 0, 0, {.bidirectional = false}).edge(1, 0, 2, 0);
  World w(std::move(g).build());
  EXPECT_EQ(plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "5,5")})).reason,
            PlanFailure::unreachable);
  EXPECT_EQ(plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "2,0")})).reason,
            PlanFailure::unreachable);
  // The one-way edge is fine the other way round.
  EXPECT_EQ(plan_ok(w, request_to(w, "a", "2,0", {open_stop(w, "0,0")})).arrival, sec(2));
}

TEST(Planner, WaitsForALockToEnd) {
  World w(GridBuilder().corridor(5).build());
  ASSERT_TRUE(w.timelines.lock(w.at("2,0"), {sec(0), sec(5)}, "op", "spill").has_value());
  EXPECT_EQ(plan_ok(w, request_to(w, "a", "0,0", {open_stop(w, "4,0")})).arrival, sec(8));
}

TEST(Planner, ReportsLockedWhenLocksBlockEveryRoute) {
  World w(GridBuilder().corridor(5).build());
  ASSERT_TRUE(w.timelines.lock(w.at("2,0"), {sec(0), kForever}, "op", "broken plate"));
  const PlanError e = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "4,0")}));
  EXPECT_EQ(e.reason, PlanFailure::locked);
}

TEST(Planner, ReportsNoWindowWhenTheGoalIsHeldForGoodByAnotherAgent) {
  World w(GridBuilder().corridor(5).build());
  w.occupy("b", "4,0", sec(3), kForever);
  const PlanError e = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "4,0")}));
  EXPECT_EQ(e.reason, PlanFailure::no_window);
  EXPECT_NE(e.message.find("agent b"), std::string::npos) << e.message;
  EXPECT_EQ(e.blockers, std::vector<std::string>{"b"});
  // A visit with a dwell needs no open-ended window.
  EXPECT_EQ(plan_ok(w, request_to(w, "a", "0,0", {dwell_stop(w, "2,0", 1)})).arrival, sec(2));
}

TEST(Planner, NamesTheAgentsStandingForGoodInTheWayAsBlockers) {
  // b stands for good in the middle of a corridor, c at its far end: no route can get past
  // b, and the failure names b (on the way) but not c (not on the way).
  World w(GridBuilder().corridor(6).build());
  w.occupy("b", "2,0", sec(0), kForever);
  w.occupy("c", "5,0", sec(0), kForever);
  const PlanError e = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "4,0")}));
  EXPECT_EQ(e.reason, PlanFailure::no_window);
  EXPECT_EQ(e.blockers, std::vector<std::string>{"b"}) << e.message;
  EXPECT_NE(e.message.find("standing in the way: b"), std::string::npos) << e.message;
  // After earlier traffic, from the very end of the last free window: still b, and only b
  // (the explanation reads the timeline from where the newcomer's windows end).
  World busy(GridBuilder().corridor(6).build());
  busy.occupy("d", "2,0", sec(0), sec(1));
  busy.occupy("b", "2,0", sec(2), kForever);
  const PlanError after_traffic =
      plan_error(busy, request_to(busy, "a", "0,0", {open_stop(busy, "4,0")}));
  EXPECT_EQ(after_traffic.reason, PlanFailure::no_window);
  EXPECT_EQ(after_traffic.blockers, std::vector<std::string>{"b"}) << after_traffic.message;
  // A stay that ends is no blocker: the route waits for it.
  World later(GridBuilder().corridor(6).build());
  later.occupy("b", "2,0", sec(0), sec(10));
  EXPECT_GT(plan_ok(later, request_to(later, "a", "0,0", {open_stop(later, "4,0")})).arrival, sec(10));
  // Locks are no agents: a corridor locked for good has no blockers.
  World locked(GridBuilder().corridor(6).build());
  ASSERT_TRUE(locked.timelines.lock(locked.at("2,0"), {sec(0), kForever}, "op", "broken plate"));
  EXPECT_TRUE(plan_error(locked, request_to(locked, "a", "0,0", {open_stop(locked, "4,0")})).blockers.empty());
}

TEST(Planner, FailsWithoutASearchWhenNoEdgeIntoTheGoalIsEverFreeToStay) {
  // b and c stand for good on both sides of the goal: no edge into it is ever free again,
  // which the arrival floor shows before any state is expanded (a search would otherwise
  // try every window it can reach within the horizon).
  World w(GridBuilder().corridor(7).build());
  w.occupy("b", "2,0", sec(0), kForever);
  w.occupy("c", "4,0", sec(0), kForever);
  const PlanError e = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "3,0")}));
  EXPECT_EQ(e.reason, PlanFailure::no_window);
  EXPECT_EQ(e.blockers, std::vector<std::string>{"b"}) << e.message;
  EXPECT_EQ(w.planner.last_stats().arrival_floor, kForever);
  // Once c leaves, the goal is still out of reach behind b, but no longer provably so
  // from the goal alone: the search runs.
  World open(GridBuilder().corridor(7).build());
  open.occupy("b", "2,0", sec(0), kForever);
  open.occupy("c", "4,0", sec(0), sec(5));
  EXPECT_EQ(plan_error(open, request_to(open, "a", "0,0", {open_stop(open, "3,0")})).reason,
            PlanFailure::no_window);
  EXPECT_LT(open.planner.last_stats().arrival_floor, kForever);
}

TEST(Planner, FailsAtOnceWhenTheGoalIsShutInBeforeAnyRouteCanGetThere) {
  // b parks for good at 9,0 from 3 s on, shutting in the goal 11,0 (and 10,0) long before a,
  // ten cells away, could get past: the shut-in proof ends the search after its first state
  // (shut_in_after = 1 here; a real search would have tried every window it can reach).
  // The outcome is the one without the proof, only sooner.
  const auto shut_in = [](TimeNs parked_from, PlannerOptions options) {
    auto w = std::make_unique<World>(GridBuilder().corridor(12).build(), options);
    w->occupy("b", "9,0", parked_from, kForever);
    return w;
  };
  const PlannerOptions proving{.shut_in_after = 1};
  const PlannerOptions searching{.shut_in_after = 0};
  auto w = shut_in(sec(3), proving);
  const PlanError e = plan_error(*w, request_to(*w, "a", "0,0", {open_stop(*w, "11,0")}));
  EXPECT_EQ(w->planner.last_stats().shut_in_proofs, 1u);
  EXPECT_EQ(w->planner.last_stats().shut_in_refusals, 1u);
  EXPECT_EQ(w->planner.last_stats().expanded, 1u);
  auto s = shut_in(sec(3), searching);
  const PlanError searched = plan_error(*s, request_to(*s, "a", "0,0", {open_stop(*s, "11,0")}));
  EXPECT_EQ(s->planner.last_stats().shut_in_proofs, 0u);
  EXPECT_GT(s->planner.last_stats().expanded, 1u);
  EXPECT_EQ(e.reason, PlanFailure::no_window);
  EXPECT_EQ(e.reason, searched.reason);
  EXPECT_EQ(e.message, searched.message);
  EXPECT_EQ(e.blockers, std::vector<std::string>{"b"}) << e.message;
  // Parked from 30 s on, b lets a in first: the region is shut in all the same, the proof
  // fails, and the search finds the route it finds without it.
  auto late = shut_in(sec(30), proving);
  const Route route = plan_ok(*late, request_to(*late, "a", "0,0", {open_stop(*late, "11,0")}));
  EXPECT_EQ(late->planner.last_stats().shut_in_proofs, 1u);
  EXPECT_EQ(late->planner.last_stats().shut_in_refusals, 0u);
  EXPECT_EQ(route.arrival, sec(11));
  // The start inside the region: nothing is shut in, no proof is tried.
  auto inside = shut_in(sec(3), proving);
  plan_ok(*inside, request_to(*inside, "a", "10,0", {open_stop(*inside, "11,0")}));
  EXPECT_EQ(inside->planner.last_stats().shut_in_proofs, 0u);
}

TEST(Planner, ReportsWhyTheStartIsNotFree) {
  World w(GridBuilder().corridor(3).build());
  w.occupy("b", "0,0", sec(0), sec(10));
  EXPECT_EQ(plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "2,0")})).reason,
            PlanFailure::no_window);
  ASSERT_TRUE(w.timelines.lock(w.at("2,0"), {sec(0), sec(10)}, "op", "inspection"));
  EXPECT_EQ(plan_error(w, request_to(w, "a", "2,0", {open_stop(w, "0,0")})).reason,
            PlanFailure::locked);
}

TEST(Planner, ABlockedStartIsReportedOnlyAfterTheChecksThatComeFirst) {
  // The planner tells a blocked start before computing the heuristic when the stops are
  // known to be reachable; the failure must be the one of the usual order all the same.
  GridBuilder g;
  g.cell(0, 0).cell(1, 0).cell(2, 0).cell(5, 5);
  g.edge(0, 0, 1, 0, {.bidirectional = false}).edge(1, 0, 2, 0);
  World w(std::move(g).build());
  w.occupy("b", "0,0", sec(0), sec(10));
  const auto start_message = [](const PlanError& e) {
    return e.message.find("start vertex '0,0' is not free") != std::string::npos;
  };
  // Reachable, though not back (one-way): the blocked start, found by the search.
  const PlanError one_way = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "2,0")}));
  EXPECT_EQ(one_way.reason, PlanFailure::no_window);
  EXPECT_TRUE(start_message(one_way)) << one_way.message;
  // Unreachable comes first.
  EXPECT_EQ(plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "5,5")})).reason,
            PlanFailure::unreachable);
  // Within a strongly connected part: the goal held for good comes first, then the start.
  World c(GridBuilder().corridor(4).build());
  c.occupy("b", "0,0", sec(0), sec(10));
  const PlanError blocked = plan_error(c, request_to(c, "a", "0,0", {open_stop(c, "3,0")}));
  EXPECT_EQ(blocked.reason, PlanFailure::no_window);
  EXPECT_TRUE(start_message(blocked)) << blocked.message;
  c.occupy("c", "3,0", sec(20), kForever);
  const PlanError goal = plan_error(c, request_to(c, "a", "0,0", {open_stop(c, "3,0")}));
  EXPECT_EQ(goal.reason, PlanFailure::no_window);
  EXPECT_NE(goal.message.find("never free for good"), std::string::npos) << goal.message;
  // A goal locked for good is not what stands in the way while the start is taken.
  World l(GridBuilder().corridor(4).build());
  l.occupy("b", "0,0", sec(0), sec(10));
  ASSERT_TRUE(l.timelines.lock(l.at("3,0"), {sec(20), kForever}, "op", "closed"));
  const PlanError locked_goal = plan_error(l, request_to(l, "a", "0,0", {open_stop(l, "3,0")}));
  EXPECT_EQ(locked_goal.reason, PlanFailure::no_window);
  EXPECT_TRUE(start_message(locked_goal)) << locked_goal.message;
}

// The explanation names what holds the goal for good, not whatever else overlaps its start
// there (here the edge its holder arrives by, whose shadow the goal's timeline carries).
TEST(Planner, AGoalHeldForGoodIsExplainedByItsOpenEndedHold) {
  World w(GridBuilder().corridor(4).build());
  w.occupy("b", "2,0-3,0", sec(5), sec(8));
  w.occupy("b", "3,0", sec(7), kForever);
  const PlanError e = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "3,0")}));
  EXPECT_EQ(e.reason, PlanFailure::no_window);
  EXPECT_NE(e.message.find("agent b route 1001 holds '3,0' [7.000 s, forever)"), std::string::npos)
      << e.message;
  // A lock for good there too does not change the reason, nor the hold named.
  ASSERT_TRUE(w.timelines.lock(w.at("3,0"), {sec(20), kForever}, "op", "closed"));
  const PlanError both = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "3,0")}));
  EXPECT_EQ(both.reason, PlanFailure::no_window);
  EXPECT_NE(both.message.find("agent b route 1001 holds '3,0' [7.000 s, forever)"), std::string::npos)
      << both.message;
}

// A route a floor proof finds waits where it must, like the search's routes: it does not
// drive back and forth over a short edge for as long as the wait lasts (it once took 1 803
// steps here, and with a 1 µm edge it ran until memory was exhausted).
TEST(Planner, ARouteFromAProofWaitsInsteadOfDrivingBackAndForth) {
  GridBuilder grid;  // A - S - G: the vehicle starts on S, must make way, and waits on A
  grid.cell(0, 0).cell(1, 0).cell(2, 0);
  grid.edge(0, 0, 1, 0, {.length = 0.01});
  grid.edge(1, 0, 2, 0);
  World w(grid.build(), PlannerOptions{.floor_proof_after = 1});  // a proof finds the route
  w.occupy("b", "2,0", sec(0), sec(30));
  w.occupy("b", "1,0", sec(10), sec(12));
  const PlanRequest request = request_to(w, "a", "1,0", {open_stop(w, "2,0")});
  const auto planned = w.planner.plan(w.timelines, request);
  ASSERT_TRUE(planned.has_value()) << planned.error().message;
  EXPECT_EQ(w.planner.last_stats().proof_routes, 1u);
  check_route(w.topology, w.timelines, request, *planned);
  EXPECT_EQ(planned->arrival, sec(31));
  // S, S-A, A (waiting), A-S, S (waiting), S-G, G.
  EXPECT_EQ(planned->steps.size(), 7u);
  EXPECT_NEAR(planned->distance, 1.02, 1e-9);
}

// `locked` means the locks alone stand in the way: with a horizon shorter than the trip no
// route exists without them either, whatever the shape of the graph.
TEST(Planner, ALockIsNotBlamedWhereTheHorizonAloneRulesOutEveryRoute) {
  for (const bool two_way : {true, false}) {
    SCOPED_TRACE(two_way ? "two-way corridor" : "one-way last edge");
    GridBuilder grid;
    grid.cell(0, 0).cell(1, 0).cell(2, 0);
    grid.edge(0, 0, 1, 0);
    grid.edge(1, 0, 2, 0, {.bidirectional = two_way});
    World w(grid.build(), PlannerOptions{.horizon = sec(1)});  // the trip takes 2 s
    ASSERT_TRUE(w.timelines.lock(w.at("0,0"), {sec(0), sec(5)}, "op", "inspection"));
    EXPECT_EQ(plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "2,0")})).reason,
              PlanFailure::no_window);
    ASSERT_TRUE(w.timelines.lock(w.at("2,0"), {sec(0), kForever}, "op", "closed"));
    EXPECT_EQ(plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "2,0")})).reason,
              PlanFailure::no_window);
  }
}

// Nor where the reservations alone rule out every route: the lock is not what stands in the way.
TEST(Planner, ALockIsNotBlamedWhereReservationsAloneRuleOutEveryRoute) {
  World w(GridBuilder().corridor(3).build());
  ASSERT_TRUE(w.timelines.lock(w.at("0,0"), {sec(0), sec(5)}, "op", "inspection"));
  w.occupy("b", "1,0", sec(0), kForever);  // parked in the only way for good
  const PlanError start = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "2,0")}));
  EXPECT_EQ(start.reason, PlanFailure::no_window) << start.message;
  ASSERT_TRUE(w.timelines.lock(w.at("2,0"), {sec(0), kForever}, "op", "closed"));
  const PlanError goal = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "2,0")}));
  EXPECT_EQ(goal.reason, PlanFailure::no_window) << goal.message;
  // Where the lock alone blocks, it is named.
  World free(GridBuilder().corridor(3).build());
  ASSERT_TRUE(free.timelines.lock(free.at("0,0"), {sec(0), sec(5)}, "op", "inspection"));
  const PlanError locked = plan_error(free, request_to(free, "a", "0,0", {open_stop(free, "2,0")}));
  EXPECT_EQ(locked.reason, PlanFailure::locked);
  EXPECT_NE(locked.message.find("start vertex '0,0' is not free at 0.000 s: lock"), std::string::npos)
      << locked.message;
  ASSERT_TRUE(free.timelines.lock(free.at("2,0"), {sec(0), kForever}, "op", "closed"));
  const PlanError closed = plan_error(free, request_to(free, "a", "1,0", {open_stop(free, "2,0")}));
  EXPECT_EQ(closed.reason, PlanFailure::locked);
  EXPECT_NE(closed.message.find("the last stop '2,0' is never free for good"), std::string::npos)
      << closed.message;
}

TEST(Planner, GivesUpAtTheHorizon) {
  World w(GridBuilder().corridor(5).build(), PlannerOptions{.horizon = sec(10)});
  w.occupy("b", "2,0", sec(0), sec(100));
  const PlanError e = plan_error(w, request_to(w, "a", "0,0", {open_stop(w, "4,0")}));
  EXPECT_EQ(e.reason, PlanFailure::no_window);
  EXPECT_NE(e.message.find("horizon"), std::string::npos) << e.message;
}

TEST(Planner, PlansSeveralStopsInOneCallHoldingEachForItsDwell) {
  World w(GridBuilder().corridor(5).build());
  const PlanRequest request =
      request_to(w, "a", "0,0", {dwell_stop(w, "4,0", 3), open_stop(w, "1,0")});
  const Route route = plan_ok(w, request);
  ASSERT_EQ(route.stop_arrivals.size(), 2u);
  EXPECT_EQ(route.stop_arrivals[0], sec(4));
  EXPECT_EQ(route.stop_arrivals[1], sec(4 + 3 + 3));
  const RouteStep& pickup = route.steps[route.stop_steps[0]];
  EXPECT_EQ(pickup.entity, w.at("4,0"));
  EXPECT_EQ(pickup.window, (Interval{sec(4), sec(4 + 3 + 1)}));  // leaves at 7 s, +1 s
  EXPECT_EQ(route.steps.back().window, (Interval{sec(10), kForever}));
}

TEST(Planner, ConsecutiveStopsAtOneVertexAreOneStep) {
  World w(GridBuilder().corridor(3).build());
  const Route route = plan_ok(
      w, request_to(w, "a", "0,0", {dwell_stop(w, "2,0", 2), dwell_stop(w, "2,0", 5)}));
  EXPECT_EQ(route.steps.size(), 5u);
  EXPECT_EQ(route.stop_arrivals, (std::vector<TimeNs>{sec(2), sec(4)}));
  EXPECT_EQ(route.steps.back().window, (Interval{sec(2), sec(9)}));
}

TEST(Planner, ALastStopWithADwellIsHeldOnlyThatLong) {
  World w(GridBuilder().corridor(3).build());
  w.occupy("b", "2,0", sec(10), kForever);
  const Route route = plan_ok(w, request_to(w, "a", "0,0", {dwell_stop(w, "2,0", 2)}));
  EXPECT_EQ(route.steps.back().window, (Interval{sec(2), sec(4)}));
}

TEST(Planner, PicksALaterWindowAtAStopWhenTheEarlyOneIsTooShortForTheDwell) {
  World w(GridBuilder().corridor(3).build());
  w.occupy("b", "2,0", sec(4), sec(6));
  // Arriving at 2 s, a 3 s dwell would run into b at 4 s: a waits and arrives at 7 s
  // (the edge into 2,0 is free from 6 s on).
  const Route route = plan_ok(w, request_to(w, "a", "0,0", {dwell_stop(w, "2,0", 3)}));
  EXPECT_EQ(route.arrival, sec(7));
}

TEST(Planner, AStartThatIsTheGoalIsHeldInPlace) {
  World w(GridBuilder().corridor(3).build());
  const Route route = plan_ok(w, request_to(w, "a", "1,0", {open_stop(w, "1,0")}, sec(7)));
  EXPECT_EQ(route.steps, (std::vector<RouteStep>{{w.at("1,0"), {sec(7), kForever}}}));
  EXPECT_EQ(route.travel_time, 0);
}

TEST(Planner, RejectsInvalidRequests) {
  World w(GridBuilder().corridor(3).build());
  const PlanRequest good = request_to(w, "a", "0,0", {dwell_stop(w, "1,0", 1), open_stop(w, "2,0")});
  std::vector<std::pair<const char*, PlanRequest>> cases;
  auto add = [&](const char* name, auto change) {
    PlanRequest r = good;
    change(r);
    cases.emplace_back(name, r);
  };
  add("unknown start", [](PlanRequest& r) { r.start = 99; });
  add("edge as start", [&](PlanRequest& r) { r.start = w.at("0,0-1,0"); });
  add("unknown stop", [](PlanRequest& r) { r.stops[1].vertex = topology::kNoEntity; });
  add("no stops", [](PlanRequest& r) { r.stops.clear(); });
  add("negative dwell", [](PlanRequest& r) { r.stops[0].dwell = -1; });
  add("zero last dwell", [](PlanRequest& r) { r.stops[1].dwell = 0; });
  add("no agent", [](PlanRequest& r) { r.agent.clear(); });
  add("zero speed", [](PlanRequest& r) { r.vehicle.max_speed = 0; });
  add("nan length", [](PlanRequest& r) { r.vehicle.length = std::nan(""); });
  add("negative payload", [](PlanRequest& r) { r.vehicle.payload = -1; });
  add("negative start time", [](PlanRequest& r) { r.start_time = -5; });
  for (const auto& [name, request] : cases) {
    SCOPED_TRACE(name);
    EXPECT_EQ(plan_error(w, request).reason, PlanFailure::invalid_request);
  }
  topology::TimelineSet wrong_size(std::vector<std::vector<topology::EntityIndex>>(2));
  auto planned = w.planner.plan(wrong_size, good);
  ASSERT_FALSE(planned.has_value());
  EXPECT_EQ(planned.error().reason, PlanFailure::invalid_request);
}

// Bad options are the caller's mistake too: every plan call refuses them, naming the option.
TEST(Planner, RejectsInvalidOptions) {
  const std::vector<std::pair<PlannerOptions, std::string>> cases = {
      {PlannerOptions{.horizon = 0}, "horizon"},
      {PlannerOptions{.floor_proof_after = 0}, "floor_proof_after"},
      {PlannerOptions{.floor_proof_budget = 0}, "floor_proof_budget"},
      {PlannerOptions{.quick_proof_after = 8, .quick_proof_budget = 0}, "quick_proof_budget"},
      {PlannerOptions{.shut_in_region = 0}, "shut_in_region"},
      {PlannerOptions{.shut_in_budget = 0}, "shut_in_budget"},
  };
  for (const auto& [options, named] : cases) {
    SCOPED_TRACE(named);
    World w(GridBuilder().corridor(3).build(), options);
    const auto planned = w.planner.plan(w.timelines, request_to(w, "a", "0,0", {open_stop(w, "2,0")}));
    ASSERT_FALSE(planned.has_value());
    EXPECT_EQ(planned.error().reason, PlanFailure::invalid_request);
    EXPECT_NE(planned.error().message.find(named), std::string::npos) << planned.error().message;
  }
  // No quick proofs at all needs no budget for them.
  World w(GridBuilder().corridor(3).build(),
          PlannerOptions{.quick_proof_after = 0, .quick_proof_budget = 0});
  EXPECT_TRUE(w.planner.plan(w.timelines, request_to(w, "a", "0,0", {open_stop(w, "2,0")})));
  // Nor do no shut-in checks.
  World unchecked(GridBuilder().corridor(3).build(),
                  PlannerOptions{.shut_in_after = 0, .shut_in_region = 0, .shut_in_budget = 0});
  EXPECT_TRUE(unchecked.planner.plan(unchecked.timelines,
                                     request_to(unchecked, "a", "0,0", {open_stop(unchecked, "2,0")})));
}

TEST(Planner, ATestRouteReservesNothing) {
  World w(GridBuilder().corridor(4).build());
  w.occupy("b", "2,0", sec(0), sec(3));
  const topology::TimelineSet before = w.timelines;
  plan_ok(w, request_to(w, "a", "0,0", {open_stop(w, "3,0")}));
  EXPECT_TRUE(w.timelines == before);
}

TEST(Planner, ARealRouteIsReservedWholeAndOthersPlanAroundIt) {
  World w(GridBuilder().corridor(6).build());
  const PlanRequest first = request_to(w, "a", "0,0", {open_stop(w, "3,0")});
  auto reserved = w.planner.plan_and_reserve(w.timelines, first, 7);
  ASSERT_TRUE(reserved.has_value()) << reserved.error().message;
  for (std::uint32_t i = 0; i < reserved->steps.size(); ++i) {
    const RouteStep& step = reserved->steps[i];
    const auto& on = w.timelines.timeline(step.entity).reservations;
    EXPECT_TRUE(std::any_of(on.begin(), on.end(), [&](const topology::Reservation& r) {
      return r.agent == "a" && r.route == 7 && r.step == i && !r.shadow() && r.window == step.window;
    })) << "step " << i;
  }
  // b stays at the far end: fine. c wants 3,0, held by a for good: refused.
  const PlanRequest second = request_to(w, "b", "5,0", {open_stop(w, "5,0")});
  ASSERT_TRUE(w.planner.plan_and_reserve(w.timelines, second, 1).has_value());
  const topology::TimelineSet before = w.timelines;
  auto refused = w.planner.plan_and_reserve(
      w.timelines, request_to(w, "c", "1,0", {open_stop(w, "3,0")}, sec(20)), 1);
  ASSERT_FALSE(refused.has_value());
  EXPECT_TRUE(w.timelines == before) << "a refused real route must change nothing";
}

TEST(Planner, HeuristicTablesReusedAcrossCallsGiveTheSameRoutes) {
  // One planner with a single cached table (multi-stop requests need several at once),
  // another that is fresh for every request: same answers.
  GridBuilder g;
  for (int x = 0; x < 4; ++x) {
    for (int y = 0; y < 3; ++y) g.cell(x, y);
  }
  for (int x = 0; x < 4; ++x) {
    for (int y = 0; y < 3; ++y) {
      if (x + 1 < 4) g.edge(x, y, x + 1, y, {.length = 1.0 + (x + y) % 3});
      if (y + 1 < 3) g.edge(x, y, x, y + 1, {.length = 1.0 + (x * y) % 2});
    }
  }
  World w(std::move(g).build(), PlannerOptions{.heuristic_tables = 1});
  w.occupy("b", "1,1", sec(0), sec(4));
  w.occupy("b", "2,2", sec(2), sec(9));
  const char* cells[] = {"0,0", "3,2", "1,2", "2,0", "0,2", "3,0"};
  for (int i = 0; i < 12; ++i) {
    const PlanRequest request =
        request_to(w, "a", cells[i % 6],
                   {dwell_stop(w, cells[(i + 1) % 6], 1), dwell_stop(w, cells[(i + 3) % 6], 2),
                    open_stop(w, cells[(i + 4) % 6])});
    Planner fresh(w.graph);
    auto expected = fresh.plan(w.timelines, request);
    auto cached = w.planner.plan(w.timelines, request);
    ASSERT_EQ(expected.has_value(), cached.has_value());
    if (!expected) continue;
    EXPECT_EQ(cached->arrival, expected->arrival) << "request " << i;
    check_route(w.topology, w.timelines, request, *cached);
  }
}

}  // namespace
}  // namespace drover::carp::test
