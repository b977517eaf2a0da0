// TimelineSet, operation by operation, on small hand-made conflict graphs: reservations and
// shadows, two-phase prepare, free windows, locks, allocation order, release and cancel.
// Delay propagation has its own file (timeline_delay_test.cpp).

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "drover/topology/timeline.hpp"
#include "tests/topology/timeline_reference.hpp"

namespace drover::topology {
namespace {

/// Conflict sets of `n` entities from unordered pairs.
std::vector<std::vector<EntityIndex>> graph(std::size_t n,
                                            std::vector<std::pair<EntityIndex, EntityIndex>> pairs) {
  std::vector<std::vector<EntityIndex>> sets(n);
  for (auto [a, b] : pairs) {
    sets[a].push_back(b);
    sets[b].push_back(a);
  }
  for (auto& s : sets) std::sort(s.begin(), s.end());
  return sets;
}

RouteStep at(EntityIndex entity, TimeNs start, TimeNs end) {
  return RouteStep{entity, Interval{start, end}};
}

std::vector<Interval> windows(std::vector<std::pair<TimeNs, TimeNs>> list) {
  std::vector<Interval> out;
  for (auto [s, e] : list) out.push_back(Interval{s, e});
  return out;
}

// Entities 0 and 1 conflict (say a vertex and an edge passing close by); 2 and 3 are free.
class TimelineTest : public ::testing::Test {
 protected:
  TimelineSet set{graph(4, {{0, 1}})};

  ErrorCode reserve_error(const AgentId& agent, RouteId route, std::vector<RouteStep> steps) {
    const TimelineSet before = set;
    const Status status = set.reserve(agent, route, steps);
    EXPECT_FALSE(status.has_value());
    EXPECT_TRUE(set == before) << "a rejected reserve changed the set";
    return status.has_value() ? ErrorCode::internal : status.error().code;
  }
};

TEST_F(TimelineTest, ExpandWritesOneRealAndAShadowPerConflictingEntity) {
  const auto items = set.expand("amy", 7, {at(0, 0, 10), at(2, 9, 20)});
  ASSERT_EQ(items.size(), 3u);
  EXPECT_EQ(items[0], (Reservation{"amy", 7, 0, 0, 0, {0, 10}, false}));
  EXPECT_EQ(items[1], (Reservation{"amy", 7, 0, 1, 0, {0, 10}, false}));
  EXPECT_TRUE(items[1].shadow());
  EXPECT_EQ(items[2], (Reservation{"amy", 7, 1, 2, 2, {9, 20}, false}));
}

TEST_F(TimelineTest, ConstructorIgnoresSelfReferencesAndUnknownEntities) {
  TimelineSet odd({{0, 1, 9}, {0}});
  EXPECT_EQ(odd.entity_count(), 2u);
  EXPECT_EQ(odd.expand("amy", 1, {at(0, 0, 5)}).size(), 2u);  // 0 itself and 9 are dropped
}

TEST_F(TimelineTest, ReserveWritesShadowsAndIncrementsVersionsOnce) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10), at(2, 8, 20)}));
  EXPECT_EQ(set.timeline(0).reservations.size(), 1u);
  ASSERT_EQ(set.timeline(1).reservations.size(), 1u);
  EXPECT_EQ(set.timeline(1).reservations[0].origin, 0u);
  EXPECT_FALSE(set.timeline(1).reservations[0].prepared);
  EXPECT_EQ(set.version(0), 1u);  // prepare and commit in one operation: one change
  EXPECT_EQ(set.version(1), 1u);
  EXPECT_EQ(set.version(2), 1u);
  EXPECT_EQ(set.version(3), 0u);
}

TEST_F(TimelineTest, OtherAgentsNeverOverlapOnAnEntityOrItsConflictSet) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 10, 20)}));
  EXPECT_EQ(reserve_error("bob", 1, {at(0, 15, 25)}), ErrorCode::conflict);
  EXPECT_EQ(reserve_error("bob", 1, {at(1, 5, 11)}), ErrorCode::conflict);  // via the shadow
  EXPECT_TRUE(set.reserve("bob", 2, {at(1, 20, 30)}));  // touching is fine: half-open
  EXPECT_TRUE(set.reserve("bob", 3, {at(2, 10, 20)}));  // 2 does not conflict with 0
  EXPECT_TRUE(set.reserve("amy", 4, {at(0, 12, 18)}));  // own reservations may overlap
}

TEST(TimelineShadows, ShadowsOfEntitiesThatDoNotConflictShareATimeline) {
  // 0 - 1 - 2: 0 and 2 do not conflict, but both conflict with 1, whose timeline then holds
  // both shadows at once (I1 is about 0 and 2 themselves, which may be used together).
  TimelineSet set(graph(3, {{0, 1}, {1, 2}}));
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10)}));
  EXPECT_TRUE(set.free_windows(2, "bob", 0, 20) == windows({{0, 20}}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 5, 15)}));
  EXPECT_EQ(set.timeline(1).reservations.size(), 2u);
  // Each shadow still stands for its real reservation: 1 itself is blocked by both.
  EXPECT_TRUE(set.free_windows(1, "cat", 0, 20) == windows({{15, 20}}));
  EXPECT_EQ(set.reserve("cat", 1, {at(1, 12, 20)}).error().code, ErrorCode::conflict);
  ASSERT_TRUE(set.reserve("cat", 2, {at(1, 20, 30)}));
  // Both may hold their entity at once; 1 waits for both (two reservations before cat's).
  EXPECT_TRUE(set.allocate("amy", 0)->granted);
  EXPECT_TRUE(set.allocate("bob", 2)->granted);
  const auto cat = set.allocate("cat", 1);
  EXPECT_FALSE(cat->granted);
  EXPECT_EQ(cat->queue_position, 2u);
  // A held shadow blocks only steps on entities its origin conflicts with: amy may come
  // back to 0 before bob's allocated step on 2 ends, as 0 and 2 do not conflict.
  EXPECT_TRUE(set.reserve("amy", 2, {at(0, 12, 14)}));
}

TEST(TimelineShadows, ADelayPushesOnlyConflictingReservations) {
  TimelineSet set(graph(3, {{0, 1}, {1, 2}}));
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 5, 15)}));
  ASSERT_TRUE(set.reserve("cat", 1, {at(1, 20, 30)}));
  const auto report = set.delay("amy", 1, 0, 15);  // amy on 0 until 25
  ASSERT_TRUE(report.has_value());
  // bob's shadow on 1 is overtaken by amy's (they do not conflict); cat waits for amy.
  EXPECT_EQ(report->shifts, (std::vector<Shift>{{"amy", 1, 0, 15}, {"cat", 1, 0, 5}}));
  EXPECT_EQ(set.timeline(2).reservations.front().window, (Interval{5, 15}));
  EXPECT_EQ(set.timeline(1).reservations.back().window, (Interval{25, 35}));
}

TEST(TimelineShadows, TheCheckerTellsConflictingShadowsFromOthers) {
  TimelineSet set(graph(3, {{0, 1}, {1, 2}}));
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 5, 15)}));
  reference::Snapshot s{graph(3, {{0, 1}, {1, 2}}), {}, {}};
  for (EntityIndex e = 0; e < 3; ++e) s.timelines.push_back(set.timeline(e));
  EXPECT_TRUE(reference::check_exclusive(s).empty());
  // The same timelines where 0 and 2 conflict (with their shadows on each other added)
  // break I1 on every timeline.
  reference::Snapshot triangle = s;
  triangle.conflicts = graph(3, {{0, 1}, {1, 2}, {0, 2}});
  triangle.timelines[2].reservations.insert(triangle.timelines[2].reservations.begin(),
                                             Reservation{"amy", 1, 0, 2, 0, {0, 10}, false});
  triangle.timelines[0].reservations.push_back(Reservation{"bob", 1, 0, 0, 2, {5, 15}, false});
  const auto violations = reference::check_exclusive(triangle);
  EXPECT_GE(violations.size(), 3u);  // on 0, on 1 (shadows), on 2; and the real pair
}

TEST_F(TimelineTest, PrepareRejectsMalformedRequestsWithInvalidArgument) {
  const auto good = set.expand("amy", 1, {at(0, 0, 10), at(2, 8, 20)});
  auto expect_invalid = [&](std::vector<Reservation> items, const char* what) {
    const TimelineSet before = set;
    const auto result = set.prepare(items, {}, 100);
    ASSERT_FALSE(result.has_value()) << what;
    EXPECT_EQ(result.error().code, ErrorCode::invalid_argument) << what;
    EXPECT_FALSE(result.error().message.empty());
    EXPECT_TRUE(set == before) << what;
  };
  expect_invalid({}, "empty");
  auto items = good;
  items[0].agent = "";
  items[1].agent = "";
  expect_invalid(items, "empty agent");
  items = good;
  items[2].agent = "bob";
  expect_invalid(items, "two agents");
  items = good;
  items[2].route = 2;
  expect_invalid(items, "two routes");
  items = good;
  items[2].window = Interval{20, 20};
  expect_invalid(items, "empty window");
  items = good;
  items[1].origin = 99;
  expect_invalid(items, "origin out of range");
  items = good;
  items[1].entity = 3;
  expect_invalid(items, "shadow outside the conflict set");
  items = good;
  items[1].window = Interval{0, 11};
  expect_invalid(items, "a step with two windows");
  items = good;
  items.push_back(good[2]);
  expect_invalid(items, "an item twice");
  // invalid_argument comes before not_found and conflict.
  items = good;
  items[0].entity = 99;
  items[2].window = Interval{5, 1};
  expect_invalid(items, "malformed and unknown");
}

TEST_F(TimelineTest, RejectionsNameTheItemAndWhatItMeets) {
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 0, 10)}));
  const auto good = set.expand("amy", 1, {at(0, 0, 10), at(2, 8, 20)});
  const auto contains = [](const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
  };
  const auto message = [&](const std::vector<Reservation>& items) {
    const auto result = set.prepare(items, {}, 100);
    return result ? std::string("accepted") : result.error().message;
  };
  auto items = good;
  items.push_back(good.back());
  EXPECT_PRED2(contains, message(items), std::string("item " + std::to_string(good.size()) +
                                                 " (entity " +
                                                 std::to_string(good.back().entity)));
  EXPECT_PRED2(contains, message(items), std::string("appears twice"));
  items = good;
  items[1].window = Interval{0, 11};
  EXPECT_PRED2(contains, message(items), std::string("item 1 "));
  EXPECT_PRED2(contains, message(items), std::string("its step has origin 0 [0, 10) in item 0"));
  // Items in any order: a step's first item is the one with the lowest index.
  items = good;
  std::reverse(items.begin(), items.end());
  const std::size_t last = items.size() - 1;  // amy's first item, of step 0
  const auto first_of_step_0 = static_cast<std::size_t>(
      std::find_if(items.begin(), items.end(), [](const Reservation& r) { return r.step == 0; }) -
      items.begin());
  ASSERT_LT(first_of_step_0, last);  // step 0 has shadows too
  items[last].window = Interval{0, 11};
  EXPECT_PRED2(contains, message(items), std::string("item " + std::to_string(last) + " "));
  EXPECT_PRED2(contains, message(items), std::string("its step has origin 0 [0, 10) in item " +
                                                     std::to_string(first_of_step_0)));
  // Well formed, but amy's second step meets bob on entity 2.
  EXPECT_PRED2(contains, message(good), std::string("prepare: item "));
  EXPECT_PRED2(contains, message(good), std::string("overlaps agent bob route 1 step 0 [0, 10)"));
}

TEST_F(TimelineTest, PrepareReportsUnknownEntitiesAndConflictsInThatOrder) {
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 0, 10)}));
  auto items = set.expand("amy", 1, {at(0, 0, 10), at(2, 5, 15)});  // 2 overlaps bob
  EXPECT_EQ(set.prepare(items, {}, 100).error().code, ErrorCode::conflict);
  items.front().entity = 77;  // unknown, and so not owned
  EXPECT_EQ(set.prepare(items, {}, 100).error().code, ErrorCode::not_found);
  EXPECT_EQ(set.prepare(set.expand("amy", 1, {at(3, 0, 10)}), {{55, 0}}, 100).error().code,
            ErrorCode::not_found);
}

// A step comes whole, as expand() writes it on the owned entities: a real item without its
// shadows would let another agent reserve a conflicting entity at the same time.
TEST(TimelinePartition, PrepareRefusesAStepWithoutTheShadowsOnOwnedEntities) {
  const std::vector<std::vector<EntityIndex>> conflicts{{1}, {0}, {}};  // 0 and 1 conflict
  TimelineSet set(conflicts);
  const Reservation real{"amy", 7, 0, 0, 0, {0, 10}, false};
  const TimelineSet before = set;
  const auto alone = set.prepare({real}, {}, 1'000);
  ASSERT_FALSE(alone.has_value());
  EXPECT_EQ(alone.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(alone.error().message.find("step 0 (entity 0) has 1 item(s) here, not 2"), std::string::npos)
      << alone.error().message;
  EXPECT_TRUE(set == before);
  // A shadow alone, its origin's real item missing where that is owned: refused too.
  EXPECT_EQ(set.prepare({Reservation{"amy", 7, 0, 1, 0, {0, 10}, false}}, {}, 1'000).error().code,
            ErrorCode::invalid_argument);
  EXPECT_TRUE(set.prepare(set.expand("amy", 7, {RouteStep{0, {0, 10}}}), {}, 1'000).has_value());

  // Across a partition border each owner gets its part: the shadow on 1 alone where only 1
  // is owned (the real item on 0 is another partition's).
  TimelineSet east(conflicts, {false, true, false});
  EXPECT_TRUE(east.prepare({Reservation{"amy", 7, 0, 1, 0, {0, 10}, false}}, {}, 1'000).has_value());
}

TEST_F(TimelineTest, PrepareChecksExpectedVersions) {
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 0, 10)}));
  const auto items = set.expand("amy", 1, {at(3, 0, 10)});
  const TimelineSet before = set;
  const auto stale = set.prepare(items, {{2, 0}}, 100);
  ASSERT_FALSE(stale.has_value());
  EXPECT_EQ(stale.error().code, ErrorCode::conflict);
  EXPECT_TRUE(set == before);
  EXPECT_TRUE(set.prepare(items, {{2, set.version(2)}, {3, 0}}, 100).has_value());
}

TEST_F(TimelineTest, PreparedItemsBlockOthersUntilCommitOrAbort) {
  const auto held = set.prepare(set.expand("amy", 1, {at(0, 0, 10)}), {}, 100);
  ASSERT_TRUE(held.has_value());
  EXPECT_TRUE(set.timeline(0).reservations[0].prepared);
  EXPECT_TRUE(set.timeline(1).reservations[0].prepared);
  EXPECT_EQ(reserve_error("bob", 1, {at(1, 5, 15)}), ErrorCode::conflict);

  ASSERT_TRUE(set.commit(*held));
  EXPECT_FALSE(set.timeline(0).reservations[0].prepared);
  EXPECT_FALSE(set.timeline(1).reservations[0].prepared);
  EXPECT_EQ(set.version(0), 2u);
  EXPECT_EQ(set.commit(*held).error().code, ErrorCode::not_found);
  EXPECT_EQ(set.abort(*held).error().code, ErrorCode::not_found);

  const auto second = set.prepare(set.expand("amy", 2, {at(2, 0, 10)}), {}, 100);
  ASSERT_TRUE(second.has_value());
  EXPECT_NE(*second, *held);
  EXPECT_EQ(reserve_error("bob", 2, {at(2, 0, 10)}), ErrorCode::conflict);
  ASSERT_TRUE(set.abort(*second));
  EXPECT_TRUE(set.timeline(2).reservations.empty());
  EXPECT_TRUE(set.reserve("bob", 2, {at(2, 0, 10)}));
}

TEST_F(TimelineTest, ARouteStepIsReservedOnlyOnce) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10)}));
  EXPECT_EQ(reserve_error("amy", 1, {at(2, 20, 30)}), ErrorCode::conflict);
}

TEST_F(TimelineTest, ExpireDropsTheDueSetsOnly) {
  const auto early = set.prepare(set.expand("amy", 1, {at(0, 0, 10)}), {}, 50);
  const auto late = set.prepare(set.expand("bob", 1, {at(2, 0, 10)}), {}, 80);
  ASSERT_TRUE(early && late);
  EXPECT_TRUE(set.expire(49).empty());
  EXPECT_EQ(set.expire(50), std::vector<PrepareId>{*early});
  EXPECT_TRUE(set.timeline(0).reservations.empty());
  EXPECT_TRUE(set.timeline(1).reservations.empty());
  EXPECT_EQ(set.commit(*early).error().code, ErrorCode::not_found);
  EXPECT_TRUE(set.commit(*late));
  EXPECT_TRUE(set.expire(1000).empty());
  EXPECT_EQ(set.timeline(2).reservations.size(), 1u);
}

TEST_F(TimelineTest, ReserveRejectsBadRoutes) {
  EXPECT_EQ(reserve_error("amy", 1, {}), ErrorCode::invalid_argument);
  EXPECT_EQ(reserve_error("", 1, {at(0, 0, 1)}), ErrorCode::invalid_argument);
  EXPECT_EQ(reserve_error("amy", 1, {at(0, 5, 5)}), ErrorCode::invalid_argument);
  EXPECT_EQ(reserve_error("amy", 1, {at(9, 0, 5)}), ErrorCode::not_found);
}

TEST(TimelinePartition, AnOwnerKeepsOnlyItsOwnEntities) {
  // Entities 0 and 1 conflict across a partition border: this set owns 0 and 2 only.
  TimelineSet part(graph(3, {{0, 1}}), {true, false, true});
  EXPECT_TRUE(part.owns(0));
  EXPECT_FALSE(part.owns(1));
  EXPECT_FALSE(part.owns(3));
  ASSERT_TRUE(part.reserve("amy", 1, {at(0, 0, 10)}));  // the shadow on 1 is the neighbour's
  EXPECT_TRUE(part.timeline(1).reservations.empty());
  EXPECT_EQ(part.reserve("amy", 2, {at(1, 20, 30)}).error().code, ErrorCode::not_found);
  EXPECT_EQ(part.allocate("amy", 1).error().code, ErrorCode::not_found);
  EXPECT_EQ(part.lock(1, {0, 5}, "op", "").error().code, ErrorCode::not_found);
  EXPECT_TRUE(part.free_windows(1, "amy", 0, 10).empty());
  // The neighbour's shadow from 1 lands here as a prepare of its own.
  const Reservation shadow{"bob", 4, 2, 0, 1, {20, 30}, false};
  EXPECT_TRUE(part.prepare({shadow}, {}, 100).has_value());
  EXPECT_EQ(part.prepare({Reservation{"bob", 5, 0, 1, 1, {40, 50}, false}}, {}, 100).error().code,
            ErrorCode::not_found);
}

TEST(TimelinePartition, ShadowsOfAStepReleasedByItsOwnerGoOnRequest) {
  // This set owns 0 and 2; 1 (the neighbour's) conflicts with 0. amy's route 7 passes 1
  // as step 3: her shadow on 0 came here as a prepare. bob comes later on 0.
  TimelineSet part(graph(3, {{0, 1}}), {true, false, true});
  auto prepared = part.prepare({Reservation{"amy", 7, 3, 0, 1, {0, 10}, false}}, {}, 100);
  ASSERT_TRUE(prepared.has_value());
  ASSERT_TRUE(part.commit(*prepared));
  ASSERT_TRUE(part.reserve("bob", 1, {at(0, 20, 30)}));
  const auto queued = part.allocate("bob", 0);
  ASSERT_TRUE(queued.has_value());
  EXPECT_FALSE(queued->granted) << "amy's shadow comes first";

  EXPECT_EQ(part.release_shadows("amy", 7, 3, 0).error().code, ErrorCode::not_permitted);  // owned here
  EXPECT_TRUE(part.release_shadows("amy", 7, 2, 1)->empty()) << "another step: nothing to remove";
  EXPECT_EQ(part.timeline(0).reservations.size(), 2u);
  const auto grants = part.release_shadows("amy", 7, 3, 1);
  ASSERT_TRUE(grants.has_value());
  EXPECT_EQ(*grants, (std::vector<Grant>{Grant{"bob", 0}}));
  EXPECT_EQ(part.timeline(0).holder, AgentId("bob"));
  EXPECT_TRUE(part.release_shadows("amy", 7, 3, 1)->empty()) << "repeated: no change";
}

TEST(TimelinePartition, CancelKeepsTheShadowsOfStepsStillHeldAbroad) {
  // As above: amy's route 7 passes the neighbour's 1 as step 3 (shadow on 0 here) and
  // goes on over 2 as step 4. Her vehicle still stands on 1 when she gives up the route.
  TimelineSet part(graph(3, {{0, 1}}), {true, false, true});
  auto prepared = part.prepare(
      {Reservation{"amy", 7, 3, 0, 1, {0, 10}, false}, Reservation{"amy", 7, 4, 2, 2, {10, 20}, false}}, {}, 100);
  ASSERT_TRUE(prepared.has_value());
  ASSERT_TRUE(part.commit(*prepared));
  ASSERT_TRUE(part.reserve("bob", 1, {at(0, 20, 30)}));

  ASSERT_TRUE(part.cancel_route("amy", 7, {3}));
  EXPECT_TRUE(part.timeline(2).reservations.empty()) << "the step ahead goes";
  ASSERT_EQ(part.timeline(0).reservations.size(), 2u) << "the shadow of the held step stays";
  EXPECT_EQ(part.timeline(0).reservations.front().agent, "amy");
  EXPECT_FALSE(part.allocate("bob", 0)->granted) << "0 stays guarded while amy stands on 1";
  // Her release at the owner of 1 is followed by the release of the shadows here.
  EXPECT_EQ(*part.release_shadows("amy", 7, 3, 1), (std::vector<Grant>{Grant{"bob", 0}}));
  // Without held steps a cancel takes the shadows with it.
  auto again = part.prepare(
      {Reservation{"amy", 8, 0, 2, 2, {40, 50}, false}, Reservation{"amy", 8, 1, 0, 1, {50, 60}, false}}, {}, 100);
  ASSERT_TRUE(again.has_value());
  ASSERT_TRUE(part.commit(*again));
  ASSERT_TRUE(part.cancel_route("amy", 8));
  for (EntityIndex e : {0u, 2u}) {
    for (const auto& r : part.timeline(e).reservations) EXPECT_NE(r.route, 8u) << "on " << e;
  }
}

// ---- free windows ---------------------------------------------------------------------

TEST_F(TimelineTest, FreeWindowsLeaveOutOthersReservationsAndLocksOnTheConflictSet) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 10, 20)}));
  ASSERT_TRUE(set.lock(1, {30, 40}, "op", "spill"));
  EXPECT_EQ(set.free_windows(0, "bob", 0, 100), windows({{0, 10}, {20, 30}, {40, 100}}));
  EXPECT_EQ(set.free_windows(1, "bob", 0, 100), windows({{0, 10}, {20, 30}, {40, 100}}));
  EXPECT_EQ(set.free_windows(0, "amy", 0, 100), windows({{0, 30}, {40, 100}}));  // own: free
  EXPECT_EQ(set.free_windows(2, "bob", 0, 100), windows({{0, 100}}));
  EXPECT_EQ(set.free_windows(0, "bob", 15, 35), windows({{20, 30}}));
  EXPECT_TRUE(set.free_windows(0, "bob", 50, 50).empty());
  EXPECT_EQ(set.free_windows(2, "bob", 0, kForever), windows({{0, kForever}}));
}

TEST_F(TimelineTest, NewcomerWindowsAreThoseOfAnAgentWithoutReservationsThere) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 10, 20)}));
  ASSERT_TRUE(set.lock(1, {30, 40}, "op", "spill"));
  const auto view = set.newcomer_windows(0);
  // From the beginning of time: what a newcomer finds from 5 on are the windows ending
  // after 5, the first from 5.
  ASSERT_EQ(view.windows().size(), 3u);
  EXPECT_EQ(view.windows()[0].end, 10);
  EXPECT_LT(view.windows()[0].start, 0);
  EXPECT_EQ(std::vector<Interval>(view.windows().begin() + 1, view.windows().end()),
            (std::vector<Interval>{{20, 30}, {40, kForever}}));
  EXPECT_EQ(set.free_windows(0, "bob", 5, kForever),
            (std::vector<Interval>{{5, 10}, {20, 30}, {40, kForever}}));
  EXPECT_TRUE(set.newcomer_windows(99).windows().empty());  // not an entity of the set
}

std::vector<EntityIndex> entities(std::span<const EntityIndex> span) {
  return {span.begin(), span.end()};
}

TEST_F(TimelineTest, ReservedEntitiesAreExactlyWhereAnAgentHasReservations) {
  EXPECT_TRUE(set.reserved_entities("amy").empty());
  // A real reservation on 0 and its shadow on 1; then a second route, over 2 and 1 (its
  // shadow on 0), and bob's on 3.
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 10, 20)}));
  EXPECT_EQ(entities(set.reserved_entities("amy")), (std::vector<EntityIndex>{0, 1}));
  ASSERT_TRUE(set.reserve("amy", 2, {at(2, 30, 40), at(1, 39, 50)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(3, 0, 5)}));
  EXPECT_EQ(entities(set.reserved_entities("amy")), (std::vector<EntityIndex>{0, 1, 2}));
  EXPECT_EQ(entities(set.reserved_entities("bob")), (std::vector<EntityIndex>{3}));
  EXPECT_TRUE(set.reserved_entities("am").empty());  // no prefix matches
  // Cancelling the first route leaves 1 (the second route's, and its shadow on 0).
  ASSERT_TRUE(set.cancel_route("amy", 1));
  EXPECT_EQ(entities(set.reserved_entities("amy")), (std::vector<EntityIndex>{0, 1, 2}));
  ASSERT_TRUE(set.cancel_route("amy", 2));
  EXPECT_TRUE(set.reserved_entities("amy").empty());
  EXPECT_EQ(entities(set.reserved_entities("bob")), (std::vector<EntityIndex>{3}));
  // A copy answers alike, and a newcomer sees every entity's windows as its own.
  const TimelineSet copy = set;
  EXPECT_EQ(entities(copy.reserved_entities("bob")), (std::vector<EntityIndex>{3}));
  EXPECT_EQ(copy.free_windows(3, "bob", 0, kForever), windows({{0, kForever}}));
  EXPECT_EQ(copy.free_windows(3, "cat", 0, kForever), windows({{5, kForever}}));
}

TEST_F(TimelineTest, ReservedEntitiesFollowPreparedSetsReplicasAndRestores) {
  const auto aborted = set.prepare(set.expand("amy", 1, {at(2, 0, 10)}), {}, 50);
  ASSERT_TRUE(aborted);
  EXPECT_EQ(entities(set.reserved_entities("amy")), (std::vector<EntityIndex>{2}));
  ASSERT_TRUE(set.abort(*aborted));
  EXPECT_TRUE(set.reserved_entities("amy").empty());
  ASSERT_TRUE(set.prepare(set.expand("amy", 2, {at(2, 0, 10)}), {}, 50));
  EXPECT_EQ(set.expire(50).size(), 1u);
  EXPECT_TRUE(set.reserved_entities("amy").empty());
  const auto committed = set.prepare(set.expand("amy", 3, {at(0, 0, 10)}), {}, 50);
  ASSERT_TRUE(committed && set.commit(*committed));
  EXPECT_EQ(entities(set.reserved_entities("amy")), (std::vector<EntityIndex>{0, 1}));

  // A copy changes alone.
  TimelineSet copy = set;
  ASSERT_TRUE(copy.cancel_route("amy", 3));
  EXPECT_TRUE(copy.reserved_entities("amy").empty());
  EXPECT_EQ(entities(set.reserved_entities("amy")), (std::vector<EntityIndex>{0, 1}));

  // Restored from a snapshot: the same.
  const auto restored = TimelineSet::restore(graph(4, {{0, 1}}), {}, set.snapshot());
  ASSERT_TRUE(restored);
  EXPECT_EQ(entities(restored->reserved_entities("amy")), (std::vector<EntityIndex>{0, 1}));
  EXPECT_EQ(restored->free_windows(1, "amy", 0, 20), windows({{0, 20}}));
  EXPECT_EQ(restored->free_windows(1, "bob", 0, 20), windows({{10, 20}}));

  // A replica's timeline replaced: amy's shadow on 1 gone, bob's reservation come. Each
  // then sees its own as free there.
  Timeline one;
  one.version = 4;
  one.reservations = {Reservation{"bob", 4, 0, 1, 1, {0, 5}, false}};
  ASSERT_TRUE(set.replace_timeline(1, one));
  EXPECT_EQ(entities(set.reserved_entities("amy")), (std::vector<EntityIndex>{0}));
  EXPECT_EQ(entities(set.reserved_entities("bob")), (std::vector<EntityIndex>{1}));
  EXPECT_EQ(set.free_windows(1, "bob", 0, 10), windows({{0, 10}}));
  EXPECT_EQ(set.free_windows(1, "amy", 0, 10), windows({{5, 10}}));
  EXPECT_EQ(set.free_windows(0, "amy", 0, 10), windows({{0, 10}}));
}

TEST_F(TimelineTest, WindowsRevisionsMoveWhenWhatFreeWindowsReadChanges) {
  const auto revisions = [](const TimelineSet& s) {
    return std::vector<std::uint64_t>{s.windows_revision(0), s.windows_revision(1),
                                      s.windows_revision(2)};
  };
  const auto before = revisions(set);
  const TimelineSet copy = set;
  EXPECT_EQ(revisions(copy), before);  // same content, same windows
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 10, 20)}));  // real on 0, shadow on 1
  auto after = revisions(set);
  EXPECT_NE(after[0], before[0]);
  EXPECT_NE(after[1], before[1]);
  EXPECT_EQ(after[2], before[2]);
  EXPECT_EQ(revisions(copy), before);  // the copy did not change
  TimelineSet other = copy;
  ASSERT_TRUE(other.reserve("bob", 1, {at(0, 50, 60)}));
  EXPECT_NE(other.windows_revision(0), set.windows_revision(0));  // never shared by chance
  const auto locked = set.lock(1, {30, 40}, "op", "spill");  // read by 0's windows too
  ASSERT_TRUE(locked);
  EXPECT_NE(set.windows_revision(0), after[0]);
  after = revisions(set);
  ASSERT_TRUE(set.allocate("amy", 0)->granted);  // amy's shadow on 1 is held now
  EXPECT_NE(set.windows_revision(1), after[1]);
}

TEST_F(TimelineTest, NobodyIsPlacedBeforeAHolder) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 50, 60)}));
  ASSERT_TRUE(set.allocate("amy", 0)->granted);
  // Amy occupies 0 now; a reservation before hers would let bob in ahead of her.
  EXPECT_EQ(set.free_windows(0, "bob", 0, 100), windows({{60, 100}}));
  EXPECT_EQ(set.free_windows(1, "bob", 0, 100), windows({{60, 100}}));
  EXPECT_EQ(reserve_error("bob", 1, {at(0, 0, 10)}), ErrorCode::conflict);
  EXPECT_EQ(reserve_error("bob", 1, {at(1, 0, 10)}), ErrorCode::conflict);
  EXPECT_TRUE(set.reserve("bob", 1, {at(1, 60, 70)}));
  EXPECT_TRUE(set.reserve("amy", 2, {at(0, 0, 10)}));  // her own are her business
}

// ---- locks ----------------------------------------------------------------------------

TEST_F(TimelineTest, LockReportsWhatItHitsAndBlocksNewReservations) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(1, 10, 20)}));
  const auto lock = set.lock(0, {5, 25}, "olga", "broken floor plate");
  ASSERT_TRUE(lock.has_value());
  ASSERT_EQ(lock->hit.size(), 2u);  // amy's reservation and bob's shadow
  EXPECT_EQ(lock->hit[0].agent, "amy");
  EXPECT_EQ(lock->hit[1].agent, "bob");
  EXPECT_TRUE(lock->hit[1].shadow());
  ASSERT_EQ(set.timeline(0).locks.size(), 1u);
  EXPECT_EQ(set.lock_count(), 1u);
  EXPECT_EQ(set.timeline(0).locks[0],
            (Lock{lock->id, 0, {5, 25}, "olga", "broken floor plate"}));
  EXPECT_EQ(set.timeline(0).reservations.size(), 2u);  // nothing is revoked

  // [20, 25) on 0 is free of others' reservations, but locked.
  EXPECT_EQ(reserve_error("cat", 1, {at(0, 21, 24)}), ErrorCode::conflict);
  EXPECT_EQ(reserve_error("amy", 2, {at(0, 21, 24)}), ErrorCode::conflict);  // locks bind all
  EXPECT_TRUE(set.free_windows(0, "cat", 0, 40) == windows({{25, 40}}));
  EXPECT_TRUE(set.reserve("cat", 2, {at(2, 5, 15)}));
  ASSERT_TRUE(set.unlock(lock->id));
  EXPECT_TRUE(set.timeline(0).locks.empty());
  EXPECT_EQ(set.lock_count(), 0u);
  EXPECT_EQ(set.unlock(lock->id).error().code, ErrorCode::not_found);
  EXPECT_EQ(set.lock_count(), 0u);
  EXPECT_TRUE(set.reserve("amy", 2, {at(0, 20, 30)}));
}

TEST_F(TimelineTest, ALockOnAConflictingEntityBlocksThroughTheShadow) {
  ASSERT_TRUE(set.lock(1, {0, 100}, "olga", "spill"));
  EXPECT_EQ(reserve_error("amy", 1, {at(0, 10, 20)}), ErrorCode::conflict);
  EXPECT_TRUE(set.free_windows(0, "amy", 0, 200) == windows({{100, 200}}));
}

TEST_F(TimelineTest, ALockTakenInThroughAReplicatedTimelineBlocksItsConflictSetUntilReplaced) {
  // A routing agent's replica gets its locks only through replace_timeline.
  Timeline published;
  published.version = 3;
  published.locks.push_back(Lock{9, 1, {0, 100}, "olga", "spill"});
  ASSERT_TRUE(set.replace_timeline(1, published));
  EXPECT_EQ(set.lock_count(), 1u);
  EXPECT_EQ(set.free_windows(0, "amy", 0, 200), windows({{100, 200}}));
  published.version = 4;
  published.locks.clear();
  ASSERT_TRUE(set.replace_timeline(1, published));
  EXPECT_EQ(set.lock_count(), 0u);
  EXPECT_EQ(set.free_windows(0, "amy", 0, 200), windows({{0, 200}}));
}

TEST_F(TimelineTest, LockRejectsBadRequests) {
  const TimelineSet before = set;
  EXPECT_EQ(set.lock(0, {5, 5}, "olga", "").error().code, ErrorCode::invalid_argument);
  EXPECT_EQ(set.lock(0, {5, 6}, "", "").error().code, ErrorCode::invalid_argument);
  EXPECT_EQ(set.lock(9, {5, 6}, "olga", "").error().code, ErrorCode::not_found);
  // Beyond the shared clock's range (planning adds to lock ends): refused, but for no end.
  EXPECT_EQ(set.lock(0, {-5, 6}, "olga", "").error().code, ErrorCode::invalid_argument);
  const auto beyond = set.lock(0, {5, kLatestTime + 1}, "olga", "");
  ASSERT_FALSE(beyond.has_value());
  EXPECT_NE(beyond.error().message.find("outside the shared clock's range"), std::string::npos) << beyond.error().message;
  EXPECT_EQ(set.lock(0, {kLatestTime, kForever - 1}, "olga", "").error().code, ErrorCode::invalid_argument);
  EXPECT_TRUE(set == before);
  EXPECT_TRUE(set.lock(0, {kLatestTime - 1, kLatestTime}, "olga", "").has_value());
  EXPECT_TRUE(set.lock(0, {kLatestTime, kForever}, "olga", "").has_value());
  set = before;
  const auto a = set.lock(0, {5, 6}, "olga", "");
  const auto b = set.lock(0, {5, 6}, "olga", "");
  ASSERT_TRUE(a && b);
  EXPECT_NE(a->id, b->id);
}

TEST_F(TimelineTest, ALockNeverRevokesAnAllocation) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10)}));
  ASSERT_TRUE(set.allocate("amy", 0)->granted);
  ASSERT_TRUE(set.lock(0, {0, 100}, "olga", "inspection"));
  EXPECT_EQ(set.timeline(0).holder, "amy");
  EXPECT_TRUE(set.allocate("amy", 0)->granted);
  EXPECT_TRUE(set.release("amy", 0).has_value());
}

// ---- allocation ---------------------------------------------------------------------

TEST_F(TimelineTest, AllocationFollowsReservationOrder) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(0, 20, 30)}));
  ASSERT_TRUE(set.reserve("cat", 1, {at(0, 40, 50)}));

  auto bob = set.allocate("bob", 0);
  ASSERT_TRUE(bob.has_value());
  EXPECT_FALSE(bob->granted);
  EXPECT_EQ(bob->queue_position, 1u);
  EXPECT_EQ(set.allocate("cat", 0)->queue_position, 2u);
  EXPECT_EQ(set.timeline(0).waiting, (std::vector<AgentId>{"bob", "cat"}));
  const auto version = set.version(0);
  EXPECT_EQ(set.allocate("bob", 0)->queue_position, 1u);  // asking again changes nothing
  EXPECT_EQ(set.version(0), version);

  EXPECT_TRUE(set.allocate("amy", 0)->granted);
  EXPECT_EQ(set.timeline(0).holder, "amy");
  EXPECT_TRUE(set.allocate("amy", 0)->granted);

  const auto grants = set.release("amy", 0);
  ASSERT_TRUE(grants.has_value());
  EXPECT_EQ(*grants, (std::vector<Grant>{{"bob", 0}}));
  EXPECT_EQ(set.timeline(0).holder, "bob");
  EXPECT_EQ(set.timeline(0).waiting, std::vector<AgentId>{"cat"});
  EXPECT_EQ(set.allocate("cat", 0)->queue_position, 1u);
  EXPECT_EQ(*set.release("bob", 0), (std::vector<Grant>{{"cat", 0}}));
  EXPECT_TRUE(set.release("cat", 0)->empty());
  EXPECT_TRUE(set.timeline(0).reservations.empty());
  EXPECT_FALSE(set.timeline(0).holder.has_value());
}

TEST_F(TimelineTest, ShadowsAndPreparedItemsQueueToo) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(1, 0, 10)}));                        // shadow on 0
  ASSERT_TRUE(set.prepare(set.expand("cat", 1, {at(0, 12, 18)}), {}, 100));  // held on 0
  ASSERT_TRUE(set.reserve("bob", 1, {at(0, 20, 30)}));
  EXPECT_EQ(set.allocate("bob", 0)->queue_position, 2u);
}

TEST_F(TimelineTest, AtMostOneHolderAmongConflictingEntities) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(1, 10, 20)}));
  EXPECT_FALSE(set.allocate("bob", 1)->granted);  // amy's shadow on 1 comes first
  EXPECT_TRUE(set.allocate("amy", 0)->granted);
  EXPECT_EQ(*set.release("amy", 0), (std::vector<Grant>{{"bob", 1}}));
  EXPECT_TRUE(set.timeline(1).waiting.empty());
}

TEST_F(TimelineTest, AllocateNeedsACommittedRealReservation) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10)}));
  ASSERT_TRUE(set.prepare(set.expand("bob", 1, {at(2, 0, 10)}), {}, 100));
  const TimelineSet before = set;
  EXPECT_EQ(set.allocate("amy", 1).error().code, ErrorCode::not_found);  // a shadow only
  EXPECT_EQ(set.allocate("bob", 2).error().code, ErrorCode::not_found);  // prepared only
  EXPECT_EQ(set.allocate("cat", 0).error().code, ErrorCode::not_found);
  EXPECT_EQ(set.allocate("amy", 9).error().code, ErrorCode::not_found);
  EXPECT_EQ(set.allocate("", 0).error().code, ErrorCode::invalid_argument);
  EXPECT_TRUE(set == before);
}

TEST_F(TimelineTest, ReleaseNeedsTheHolderAndRemovesTheHeldStepOnly) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10), at(2, 9, 20), at(0, 19, 30)}));
  EXPECT_EQ(set.release("amy", 0).error().code, ErrorCode::not_permitted);
  EXPECT_FALSE(set.allocated_step(0).has_value());
  ASSERT_TRUE(set.allocate("amy", 0)->granted);
  EXPECT_EQ(set.allocated_step(0), (AllocatedStep{1, 0}));  // the first visit of 0
  EXPECT_FALSE(set.allocated_step(1).has_value());
  EXPECT_EQ(set.release("bob", 0).error().code, ErrorCode::not_permitted);
  EXPECT_EQ(set.release("amy", 9).error().code, ErrorCode::not_found);
  ASSERT_TRUE(set.release("amy", 0).has_value());
  EXPECT_FALSE(set.allocated_step(0).has_value());
  // The first visit of 0 and its shadow are gone; the second visit and step 1 stay.
  ASSERT_EQ(set.timeline(0).reservations.size(), 1u);
  EXPECT_EQ(set.timeline(0).reservations[0].step, 2u);
  ASSERT_EQ(set.timeline(1).reservations.size(), 1u);
  EXPECT_EQ(set.timeline(1).reservations[0].step, 2u);
  EXPECT_EQ(set.timeline(2).reservations.size(), 1u);
}

TEST_F(TimelineTest, CancelKeepsTheAllocatedStepAndGrantsWhoWaited) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10), at(2, 9, 20)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 30, 40)}));
  ASSERT_TRUE(set.allocate("amy", 0)->granted);
  EXPECT_FALSE(set.allocate("bob", 2)->granted);

  const auto grants = set.cancel_route("amy", 1);
  ASSERT_TRUE(grants.has_value());
  EXPECT_EQ(*grants, (std::vector<Grant>{{"bob", 2}}));
  EXPECT_EQ(set.timeline(0).reservations.size(), 1u);  // allocated: stays until released
  EXPECT_EQ(set.timeline(1).reservations.size(), 1u);  // with its shadow
  EXPECT_EQ(set.timeline(0).holder, "amy");
  EXPECT_TRUE(set.release("amy", 0).has_value());
  EXPECT_TRUE(set.timeline(0).reservations.empty());
  EXPECT_EQ(set.cancel_route("amy", 1).error().code, ErrorCode::not_found);
  EXPECT_EQ(set.cancel_route("amy", 42).error().code, ErrorCode::not_found);
}

TEST_F(TimelineTest, HoldingsOfAnAgentNameWhatItHoldsAndEveryRouteItHasItemsOf) {
  EXPECT_EQ(set.holdings_of("amy"), AgentHoldings{});
  ASSERT_TRUE(set.reserve("amy", 7, {at(0, 0, 10), at(2, 9, 20)}));
  ASSERT_TRUE(set.reserve("amy", 3, {at(2, 30, 40)}));
  ASSERT_TRUE(set.prepare(set.expand("amy", 9, {at(3, 50, 60)}), {}, 100));  // prepared only
  ASSERT_TRUE(set.reserve("bob", 1, {at(3, 0, 10)}));
  ASSERT_TRUE(set.allocate("amy", 0)->granted);
  ASSERT_TRUE(set.allocate("bob", 3)->granted);
  const TimelineSet before = set;
  const AgentHoldings amy = set.holdings_of("amy");
  EXPECT_EQ(amy.held, (std::vector<std::pair<EntityIndex, AllocatedStep>>{{0, AllocatedStep{7, 0}}}));
  EXPECT_EQ(amy.routes, (std::vector<RouteId>{3, 7, 9}));
  EXPECT_EQ(set.holdings_of("bob").held, (std::vector<std::pair<EntityIndex, AllocatedStep>>{{3, AllocatedStep{1, 0}}}));
  EXPECT_EQ(set.holdings_of("cat"), AgentHoldings{});
  EXPECT_TRUE(set == before);  // a query
}

TEST_F(TimelineTest, CancelWithdrawsWaitingRequestsAndPreparedSets) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 20, 30)}));
  EXPECT_FALSE(set.allocate("bob", 2)->granted);
  const auto held = set.prepare(set.expand("bob", 1 + 1, {at(3, 0, 10)}), {}, 100);
  ASSERT_TRUE(held.has_value());
  ASSERT_TRUE(set.cancel_route("bob", 1));
  EXPECT_TRUE(set.timeline(2).waiting.empty());
  ASSERT_TRUE(set.cancel_route("bob", 2));
  EXPECT_EQ(set.commit(*held).error().code, ErrorCode::not_found);
  EXPECT_TRUE(set.timeline(3).reservations.empty());
}

TEST_F(TimelineTest, AbortExpireAndCommitGrantThroughTakeGrants) {
  // Cat's held (prepared) item on 0 comes before amy's reservation.
  const auto held = set.prepare(set.expand("cat", 1, {at(0, 0, 10)}), {}, 100);
  ASSERT_TRUE(held.has_value());
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 20, 30)}));
  EXPECT_EQ(set.allocate("amy", 0)->queue_position, 1u);
  ASSERT_TRUE(set.abort(*held));
  EXPECT_EQ(set.take_grants(), (std::vector<Grant>{{"amy", 0}}));
  EXPECT_TRUE(set.take_grants().empty());

  ASSERT_TRUE(set.prepare(set.expand("cat", 2, {at(2, 0, 10)}), {}, 100));
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 20, 30)}));
  EXPECT_FALSE(set.allocate("bob", 2)->granted);
  EXPECT_EQ(set.expire(100).size(), 1u);
  EXPECT_EQ(set.take_grants(), (std::vector<Grant>{{"bob", 2}}));

  // Bob waits behind amy on 3, then commits a new route that is first there.
  ASSERT_TRUE(set.reserve("amy", 2, {at(3, 50, 60)}));
  ASSERT_TRUE(set.reserve("bob", 2, {at(3, 70, 80)}));
  EXPECT_FALSE(set.allocate("bob", 3)->granted);
  ASSERT_TRUE(set.reserve("bob", 3, {at(3, 0, 10)}));
  EXPECT_EQ(set.take_grants(), (std::vector<Grant>{{"bob", 3}}));
  EXPECT_EQ(set.timeline(3).holder, "bob");
}

TEST_F(TimelineTest, VersionsMoveOnEveryChangeOnly) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10)}));
  EXPECT_EQ(set.version(0), 1u);
  ASSERT_TRUE(set.allocate("amy", 0)->granted);
  EXPECT_EQ(set.version(0), 2u);
  EXPECT_EQ(set.version(1), 1u);  // the holder is 0's, not 1's
  ASSERT_TRUE(set.allocate("amy", 0)->granted);
  EXPECT_EQ(set.version(0), 2u);
  ASSERT_TRUE(set.lock(2, {0, 1}, "olga", ""));
  EXPECT_EQ(set.version(2), 1u);
  EXPECT_EQ(set.version(99), 0u);
}

// The invariant checkers of the randomised test must be able to fail: each is shown a
// state that breaks what it checks.
namespace ref = reference;

ref::Snapshot snapshot_of(const TimelineSet& set, std::map<EntityIndex, ref::HeldStep> held = {}) {
  ref::Snapshot s;
  for (EntityIndex e = 0; e < set.entity_count(); ++e) {
    s.timelines.push_back(set.timeline(e));
  }
  s.conflicts = graph(4, {{0, 1}});
  s.held = std::move(held);
  return s;
}

TEST_F(TimelineTest, CheckersAcceptAGoodStateAndCatchBrokenOnes) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(0, 20, 30)}));
  ASSERT_TRUE(set.allocate("amy", 0)->granted);
  EXPECT_FALSE(set.allocate("bob", 0)->granted);
  const std::map<EntityIndex, ref::HeldStep> held{{0, {"amy", 1, 0}}};
  const ref::Snapshot good = snapshot_of(set, held);
  EXPECT_TRUE(ref::check_exclusive(good).empty());
  EXPECT_TRUE(ref::check_allocations(good).empty());
  EXPECT_TRUE(ref::check_locks(good, {}).empty());

  ref::Snapshot overlap = good;  // bob moved onto amy on 0, his shadow too
  overlap.timelines[0].reservations[1].window = {5, 30};
  overlap.timelines[1].reservations[1].window = {5, 30};
  EXPECT_FALSE(ref::check_exclusive(overlap).empty());

  ref::Snapshot lost_shadow = good;
  lost_shadow.timelines[1].reservations.pop_back();
  EXPECT_FALSE(ref::check_exclusive(lost_shadow).empty());

  ref::Snapshot overtaken = good;  // bob holds 0 although amy's reservation comes first
  overtaken.timelines[0].holder = "bob";
  overtaken.timelines[0].waiting.clear();
  overtaken.held[0] = {"bob", 1, 0};
  EXPECT_FALSE(ref::check_allocations(overtaken).empty());

  ref::Snapshot two_holders = good;  // bob holds 1, which conflicts with amy's 0
  two_holders.timelines[1].holder = "bob";
  two_holders.held[1] = {"bob", 1, 0};
  EXPECT_FALSE(ref::check_allocations(two_holders).empty());

  ref::Snapshot forgotten = good;  // amy gone, bob still waits although he is first now
  forgotten.timelines[0].holder.reset();
  forgotten.held.clear();
  forgotten.timelines[0].reservations.erase(forgotten.timelines[0].reservations.begin());
  EXPECT_FALSE(ref::check_allocations(forgotten).empty());

  ref::Snapshot locked = good;
  locked.timelines[0].locks.push_back(Lock{7, 0, {25, 26}, "olga", ""});
  EXPECT_FALSE(ref::check_locks(locked, {}).empty());
  EXPECT_TRUE(ref::check_locks(locked, {{ref::key_of(locked.timelines[0].reservations[1]), 7}})
                  .empty());
}

// A replica of two partitions: entity 0 (one owner) carries amy's step 3 where her delay
// already moved it, its conflicting neighbour 1 (the other owner) still the shadow where it
// was. Planned on that, bob could take 1 in the gap, after amy's step there and before it
// on 0: the allocation orders would cross. Widened, each copy spans the hull.
TEST(TimelineReplica, StepHullsCloseTheGapBetweenCopiesThatOwnersMovedApart) {
  TimelineSet replica{graph(3, {{0, 1}})};
  Timeline zero;
  zero.version = 5;
  zero.reservations = {Reservation{"amy", 7, 3, 0, 0, {20, 22}, false}};
  Timeline one;
  one.version = 9;
  one.reservations = {Reservation{"amy", 7, 3, 1, 0, {10, 12}, false},
                      Reservation{"cat", 2, 0, 1, 1, {30, 31}, false}};
  ASSERT_TRUE(replica.replace_timeline(0, zero));
  ASSERT_TRUE(replica.replace_timeline(1, one));
  EXPECT_TRUE(replica.free_windows(1, "bob", 0, 40) == windows({{0, 10}, {12, 30}, {31, 40}}));

  const auto revision_of_zero = replica.windows_revision(0);
  const auto revision_of_two = replica.windows_revision(2);
  replica.widen_to_step_hulls();
  EXPECT_NE(replica.windows_revision(0), revision_of_zero) << "a planner must not keep the old windows";
  EXPECT_EQ(replica.windows_revision(2), revision_of_two) << "nothing changed there";
  EXPECT_EQ(replica.timeline(0).reservations.front().window, (Interval{10, 22}));
  EXPECT_EQ(replica.timeline(1).reservations.front().window, (Interval{10, 22}));
  EXPECT_EQ(replica.timeline(1).reservations.back().window, (Interval{30, 31}));
  EXPECT_EQ(replica.version(0), 5u);
  EXPECT_EQ(replica.version(1), 9u);
  EXPECT_TRUE(replica.free_windows(1, "bob", 0, 40) == windows({{0, 10}, {22, 30}, {31, 40}}));
  EXPECT_TRUE(replica.free_windows(0, "bob", 0, 40) == windows({{0, 10}, {22, 40}}));
}

}  // namespace
}  // namespace drover::topology
