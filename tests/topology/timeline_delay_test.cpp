// TimelineSet::delay: the delayed route waits longer at one step and moves on later; later
// reservations of others that it runs into are pushed (transitively), never reordered,
// each by no more than needed; everyone moved is reported.

#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <string>
#include <vector>

#include "drover/topology/timeline.hpp"
#include "tests/topology/timeline_reference.hpp"

namespace drover::topology {
namespace {

RouteStep at(EntityIndex entity, TimeNs start, TimeNs end) {
  return RouteStep{entity, Interval{start, end}};
}

/// The windows of (agent, route) on an entity, in timeline order.
std::vector<Interval> windows_of(const TimelineSet& set, EntityIndex entity, const AgentId& agent,
                                 RouteId route) {
  std::vector<Interval> out;
  for (const Reservation& r : set.timeline(entity).reservations) {
    if (r.agent == agent && r.route == route) out.push_back(r.window);
  }
  return out;
}

using W = std::vector<Interval>;

// Six entities; 0 and 1 conflict, the others are free of each other.
class TimelineDelay : public ::testing::Test {
 protected:
  std::vector<std::vector<EntityIndex>> conflicts{{1}, {0}, {}, {}, {}, {}};
  TimelineSet set{conflicts};
};

TEST_F(TimelineDelay, TheDelayedRouteWaitsLongerAndMovesOnByExactlyTheDelay) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10), at(3, 8, 20), at(4, 18, kForever)}));
  const auto report = set.delay("amy", 1, 2, 5);
  ASSERT_TRUE(report.has_value());
  EXPECT_EQ(windows_of(set, 2, "amy", 1), (W{{0, 15}}));
  EXPECT_EQ(windows_of(set, 3, "amy", 1), (W{{13, 25}}));
  EXPECT_EQ(windows_of(set, 4, "amy", 1), (W{{23, kForever}}));  // open ends stay open
  EXPECT_EQ(report->shifts, (std::vector<Shift>{{"amy", 1, 0, 5}}));
  EXPECT_TRUE(report->hit_locks.empty());
  EXPECT_EQ(set.version(2), 2u);  // reserve, delay
  EXPECT_EQ(set.version(4), 2u);
  EXPECT_EQ(set.version(5), 0u);
}

TEST_F(TimelineDelay, StepsBeforeTheDelayedOneStay) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10), at(3, 8, 20), at(4, 18, 30)}));
  const auto report = set.delay("amy", 1, 3, 4);
  ASSERT_TRUE(report.has_value());
  EXPECT_EQ(windows_of(set, 2, "amy", 1), (W{{0, 10}}));
  EXPECT_EQ(windows_of(set, 3, "amy", 1), (W{{8, 24}}));
  EXPECT_EQ(windows_of(set, 4, "amy", 1), (W{{22, 34}}));
  EXPECT_EQ(report->shifts, (std::vector<Shift>{{"amy", 1, 1, 4}}));
  EXPECT_EQ(set.version(2), 1u);
}

TEST_F(TimelineDelay, APushedAgentWaitsAtItsPreviousStep) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 7, {at(3, 0, 12), at(2, 10, 20), at(4, 18, 30)}));
  const auto report = set.delay("amy", 1, 2, 5);
  ASSERT_TRUE(report.has_value());
  EXPECT_EQ(windows_of(set, 2, "amy", 1), (W{{0, 15}}));
  EXPECT_EQ(windows_of(set, 3, "bob", 7), (W{{0, 17}}));  // waits 5 longer on 3
  EXPECT_EQ(windows_of(set, 2, "bob", 7), (W{{15, 25}}));  // enters 2 when amy has left
  EXPECT_EQ(windows_of(set, 4, "bob", 7), (W{{23, 35}}));
  EXPECT_EQ(report->shifts, (std::vector<Shift>{{"amy", 1, 0, 5}, {"bob", 7, 0, 5}}));
}

TEST_F(TimelineDelay, APushIsNoLargerThanNeeded) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 7, {at(3, 0, 14), at(2, 12, 20)}));  // 2 ns of slack
  const auto report = set.delay("amy", 1, 2, 5);
  ASSERT_TRUE(report.has_value());
  EXPECT_EQ(windows_of(set, 3, "bob", 7), (W{{0, 17}}));
  EXPECT_EQ(windows_of(set, 2, "bob", 7), (W{{15, 23}}));
  EXPECT_EQ(report->shifts, (std::vector<Shift>{{"amy", 1, 0, 5}, {"bob", 7, 0, 3}}));

  // Far enough away, nobody is pushed.
  ASSERT_TRUE(set.reserve("cat", 1, {at(5, 0, 10), at(2, 40, 50)}));
  const auto quiet = set.delay("amy", 1, 2, 1);
  ASSERT_TRUE(quiet.has_value());
  EXPECT_EQ(quiet->shifts.size(), 2u);  // amy, and bob once more
  EXPECT_EQ(windows_of(set, 2, "cat", 1), (W{{40, 50}}));
}

TEST_F(TimelineDelay, AFirstStepMovesWhole) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 7, {at(2, 10, 20), at(4, 18, 30)}));
  const auto report = set.delay("amy", 1, 2, 5);
  ASSERT_TRUE(report.has_value());
  EXPECT_EQ(windows_of(set, 2, "bob", 7), (W{{15, 25}}));
  EXPECT_EQ(windows_of(set, 4, "bob", 7), (W{{23, 35}}));
  EXPECT_EQ(report->shifts, (std::vector<Shift>{{"amy", 1, 0, 5}, {"bob", 7, 0, 5}}));
}

TEST_F(TimelineDelay, PushesPropagateTransitivelyAndSpareOthers) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 10, 20), at(3, 18, 30)}));
  ASSERT_TRUE(set.reserve("cat", 1, {at(5, 0, 32), at(3, 30, 40)}));
  ASSERT_TRUE(set.reserve("dan", 1, {at(4, 0, 100)}));          // elsewhere
  ASSERT_TRUE(set.reserve("eve", 1, {at(3, 0, 5)}));            // before bob and cat on 3
  const auto report = set.delay("amy", 1, 2, 5);
  ASSERT_TRUE(report.has_value());
  EXPECT_EQ(windows_of(set, 3, "bob", 1), (W{{23, 35}}));
  EXPECT_EQ(windows_of(set, 5, "cat", 1), (W{{0, 37}}));
  EXPECT_EQ(windows_of(set, 3, "cat", 1), (W{{35, 45}}));
  EXPECT_EQ(windows_of(set, 4, "dan", 1), (W{{0, 100}}));
  EXPECT_EQ(windows_of(set, 3, "eve", 1), (W{{0, 5}}));
  EXPECT_EQ(report->shifts, (std::vector<Shift>{{"amy", 1, 0, 5}, {"bob", 1, 0, 5}, {"cat", 1, 0, 5}}));
}

TEST_F(TimelineDelay, ShadowsPushToo) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(1, 10, 20)}));  // its shadow on 0 follows amy
  const auto report = set.delay("amy", 1, 0, 5);
  ASSERT_TRUE(report.has_value());
  EXPECT_EQ(windows_of(set, 1, "amy", 1), (W{{0, 15}}));  // amy's shadow
  EXPECT_EQ(windows_of(set, 1, "bob", 1), (W{{15, 25}}));
  EXPECT_EQ(windows_of(set, 0, "bob", 1), (W{{15, 25}}));  // bob's shadow
  EXPECT_EQ(report->shifts.size(), 2u);
}

TEST_F(TimelineDelay, CanBeNamedThroughAShadow) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(0, 0, 10), at(2, 8, 20)}));
  ASSERT_TRUE(set.delay("amy", 1, 1, 5).has_value());  // 1 holds the shadow of step 0
  EXPECT_EQ(windows_of(set, 0, "amy", 1), (W{{0, 15}}));
  EXPECT_EQ(windows_of(set, 2, "amy", 1), (W{{13, 25}}));
}

TEST_F(TimelineDelay, ReportsWhatItMovesIntoLocks) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 10, 20), at(4, 18, 30)}));
  const auto lock = set.lock(4, {32, 40}, "olga", "spill");
  ASSERT_TRUE(lock.has_value());
  EXPECT_TRUE(lock->hit.empty());
  const auto report = set.delay("amy", 1, 2, 5);
  ASSERT_TRUE(report.has_value());
  ASSERT_EQ(report->hit_locks.size(), 1u);
  EXPECT_EQ(report->hit_locks[0].agent, "bob");
  EXPECT_EQ(report->hit_locks[0].entity, 4u);
  EXPECT_EQ(report->hit_locks[0].window, (Interval{23, 35}));
}

TEST_F(TimelineDelay, AllocationsAndQueuesStay) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 10, 20)}));
  ASSERT_TRUE(set.allocate("amy", 2)->granted);
  EXPECT_EQ(set.allocate("bob", 2)->queue_position, 1u);
  ASSERT_TRUE(set.delay("amy", 1, 2, 50).has_value());
  EXPECT_EQ(set.timeline(2).holder, "amy");
  EXPECT_EQ(set.timeline(2).waiting, std::vector<AgentId>{"bob"});
  EXPECT_EQ(set.allocate("bob", 2)->queue_position, 1u);
  EXPECT_EQ(windows_of(set, 2, "bob", 1), (W{{60, 70}}));
}

TEST_F(TimelineDelay, PreparedItemsMoveAndStillCommit) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10)}));
  const auto held = set.prepare(set.expand("bob", 1, {at(2, 10, 20)}), {}, 100);
  ASSERT_TRUE(held.has_value());
  ASSERT_TRUE(set.delay("amy", 1, 2, 5).has_value());
  EXPECT_EQ(windows_of(set, 2, "bob", 1), (W{{15, 25}}));
  ASSERT_TRUE(set.commit(*held));
  EXPECT_FALSE(set.timeline(2).reservations.back().prepared);
}

TEST_F(TimelineDelay, AnOpenEndedLastStepHasNothingToMove) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, kForever)}));
  const TimelineSet before = set;
  const auto report = set.delay("amy", 1, 2, 5);
  ASSERT_TRUE(report.has_value());
  EXPECT_EQ(report->shifts, (std::vector<Shift>{{"amy", 1, 0, 5}}));
  EXPECT_TRUE(set == before);
}

TEST_F(TimelineDelay, RejectsBadRequestsAndChangesNothing) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10), at(3, 8, std::numeric_limits<TimeNs>::max() - 3)}));
  const TimelineSet before = set;
  EXPECT_EQ(set.delay("amy", 1, 2, 0).error().code, ErrorCode::invalid_argument);
  EXPECT_EQ(set.delay("amy", 1, 2, -4).error().code, ErrorCode::invalid_argument);
  EXPECT_EQ(set.delay("", 1, 2, 4).error().code, ErrorCode::invalid_argument);
  EXPECT_EQ(set.delay("amy", 1, 77, 4).error().code, ErrorCode::not_found);
  EXPECT_EQ(set.delay("amy", 1, 4, 4).error().code, ErrorCode::not_found);
  EXPECT_EQ(set.delay("amy", 2, 2, 4).error().code, ErrorCode::not_found);
  EXPECT_EQ(set.delay("bob", 1, 2, 4).error().code, ErrorCode::not_found);
  // Step 1 would end at or past the end of time.
  const auto overflow = set.delay("amy", 1, 2, 3);
  ASSERT_FALSE(overflow.has_value());
  EXPECT_EQ(overflow.error().code, ErrorCode::invalid_argument);
  EXPECT_TRUE(set == before);
  EXPECT_TRUE(set.delay("amy", 1, 2, 2).has_value());
}

// A delay the size of the clock's range pushes the routes behind it past the end of time
// too: refused, with nothing changed, and no time computed on the way overflows (the
// sanitized run of this test aborts on signed overflow).
TEST_F(TimelineDelay, ADelayPushingOthersPastTheEndOfTimeIsRefused) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10), at(3, 8, 20)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 10, 20), at(4, 18, 30)}));
  const TimelineSet before = set;
  const auto huge = set.delay("amy", 1, 2, std::numeric_limits<TimeNs>::max() - 5);
  ASSERT_FALSE(huge.has_value());
  EXPECT_EQ(huge.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(huge.error().message.find("past the end of time"), std::string::npos) << huge.error().message;
  EXPECT_TRUE(set == before);
}

// check_delay, the I3 checker of the randomised test, must catch broken delays.
TEST_F(TimelineDelay, TheCheckerCatchesBrokenDelays) {
  ASSERT_TRUE(set.reserve("amy", 1, {at(2, 0, 10), at(3, 8, 20)}));
  ASSERT_TRUE(set.reserve("bob", 1, {at(2, 10, 20), at(4, 18, 30)}));
  ASSERT_TRUE(set.reserve("cat", 1, {at(5, 0, 10)}));
  const auto snap = [&](const TimelineSet& s) {
    reference::Snapshot out{conflicts, {}, {}};
    for (EntityIndex e = 0; e < s.entity_count(); ++e) out.timelines.push_back(s.timeline(e));
    return out;
  };
  const reference::Snapshot before = snap(set);
  const auto report = set.delay("amy", 1, 2, 5);
  ASSERT_TRUE(report.has_value());
  const reference::Snapshot after = snap(set);
  EXPECT_TRUE(reference::check_delay(before, after, "amy", 1, 0, 5, *report).empty());

  auto bad = after;  // bob overtakes amy on 2
  bad.timelines[2].reservations[1].window = {0, 1};
  EXPECT_FALSE(reference::check_delay(before, bad, "amy", 1, 0, 5, *report).empty());
  bad = after;  // amy's later step moved too little
  bad.timelines[3].reservations[0].window.start -= 1;
  EXPECT_FALSE(reference::check_delay(before, bad, "amy", 1, 0, 5, *report).empty());
  bad = after;  // cat moved but is not reported
  bad.timelines[5].reservations[0].window = {1, 11};
  EXPECT_FALSE(reference::check_delay(before, bad, "amy", 1, 0, 5, *report).empty());
  auto fake = *report;  // cat reported but never moved
  fake.shifts.push_back(Shift{"cat", 1, 0, 5});
  EXPECT_FALSE(reference::check_delay(before, after, "amy", 1, 0, 5, fake).empty());
  fake = *report;  // bob not reported
  fake.shifts.pop_back();
  EXPECT_FALSE(reference::check_delay(before, after, "amy", 1, 0, 5, fake).empty());
  fake = *report;  // a lock hit that did not happen
  fake.hit_locks.push_back(after.timelines[4].reservations[0]);
  EXPECT_FALSE(reference::check_delay(before, after, "amy", 1, 0, 5, fake).empty());
  bad = after;  // bob pushed one further than needed (and reported so)
  for (EntityIndex e : {2u, 4u}) {
    for (Reservation& r : bad.timelines[e].reservations) {
      if (r.agent == "bob") r.window = {r.window.start + 1, r.window.end + 1};
    }
  }
  fake = *report;
  fake.shifts[1].by += 1;
  const auto violations = reference::check_delay(before, bad, "amy", 1, 0, 5, fake);
  ASSERT_EQ(violations.size(), 1u);
  EXPECT_NE(violations[0].find("further than needed"), std::string::npos);
  bad = after;  // a holder appeared
  bad.timelines[2].holder = "bob";
  EXPECT_FALSE(reference::check_delay(before, bad, "amy", 1, 0, 5, *report).empty());
}

}  // namespace
}  // namespace drover::topology
