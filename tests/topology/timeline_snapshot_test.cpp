// TimelineSet::snapshot / restore: what a topology agent journals and rebuilds on restart.
// Round trips after random operation sequences (whole topology and partition), a restored
// set that keeps working exactly like the original, presumed abort of prepared holds and
// waiting requests, and rejection of every kind of inconsistent snapshot.

#include <gtest/gtest.h>

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "drover/topology/timeline.hpp"
#include "tests/topology/timeline_reference.hpp"
#include "tests/topology/timeline_workload.hpp"

namespace drover::topology {
namespace {

using test::TimelineWorkload;

/// What the timeline of `entity` must look like after a restart: committed reservations
/// only, nobody waiting, at the version the snapshot recorded.
Timeline committed_view(const TimelineSet& set, const TimelineSnapshot& s, EntityIndex entity) {
  Timeline t = set.timeline(entity);
  std::erase_if(t.reservations, [](const Reservation& r) { return r.prepared; });
  t.waiting.clear();
  t.version = 0;
  for (const EntitySnapshot& es : s.entities) {
    if (es.entity == entity) t.version = es.version;
  }
  return t;
}

bool has_uncommitted(const TimelineSet& set) {
  for (EntityIndex e = 0; e < set.entity_count(); ++e) {
    if (!set.owns(e)) continue;
    const Timeline& t = set.timeline(e);
    if (!t.waiting.empty()) return true;
    for (const Reservation& r : t.reservations) {
      if (r.prepared) return true;
    }
  }
  return false;
}

struct RoundTripCase {
  std::uint64_t seed;
  bool partition;  ///< own about two thirds of the entities, with neighbours' shadows
};

class SnapshotRoundTrip : public ::testing::TestWithParam<RoundTripCase> {};

TEST_P(SnapshotRoundTrip, RestoreRebuildsTheCommittedState) {
  const auto [seed, partition] = GetParam();
  const auto conflicts = test::random_conflicts(seed, 8 + seed % 5, 0.25);
  std::vector<bool> owned;
  if (partition) {
    for (EntityIndex e = 0; e < conflicts.size(); ++e) owned.push_back(e % 3 != 0);
  }
  TimelineSet set(conflicts, owned);
  TimelineWorkload workload(seed, conflicts, owned);
  std::size_t held = 0, reserved = 0, locked = 0, uncommitted = 0;
  for (int op = 0; op < 800; ++op) {
    const std::string last = workload.apply(set);
    if (op % 20 != 19) continue;
    SCOPED_TRACE("after operation " + std::to_string(op) + ": " + last);
    const TimelineSnapshot s = set.snapshot();
    auto restored = TimelineSet::restore(conflicts, owned, s);
    ASSERT_TRUE(restored) << restored.error().message;
    EXPECT_TRUE(restored->snapshot() == s);
    for (EntityIndex e = 0; e < conflicts.size(); ++e) {
      if (!set.owns(e)) {
        EXPECT_FALSE(restored->owns(e));
        continue;
      }
      EXPECT_EQ(restored->timeline(e), committed_view(set, s, e)) << "entity " << e;
      EXPECT_EQ(restored->allocated_step(e), set.allocated_step(e)) << "entity " << e;
      held += set.allocated_step(e).has_value();
      reserved += set.timeline(e).reservations.size();
      locked += set.timeline(e).locks.size();
    }
    uncommitted += has_uncommitted(set);
    if (!partition) {  // the invariant checkers need every entity's timeline
      reference::Snapshot judged{conflicts, {}, {}};
      for (EntityIndex e = 0; e < conflicts.size(); ++e) {
        judged.timelines.push_back(restored->timeline(e));
        if (const auto step = restored->allocated_step(e)) {
          judged.held[e] = {*restored->timeline(e).holder, step->route, step->step};
        }
      }
      for (const auto& violations :
           {reference::check_exclusive(judged), reference::check_allocations(judged)}) {
        for (const std::string& v : violations) ADD_FAILURE() << v;
      }
    }
  }
  // Not vacuous: the snapshots carried allocations, reservations, locks, and left out
  // prepared holds or waiting requests several times.
  EXPECT_GE(held, 10u);
  EXPECT_GE(reserved, 100u);
  EXPECT_GE(locked, 10u);
  EXPECT_GE(uncommitted, 5u);
}

INSTANTIATE_TEST_SUITE_P(
    Seeds, SnapshotRoundTrip,
    ::testing::Values(RoundTripCase{1, false}, RoundTripCase{2, false}, RoundTripCase{3, false},
                      RoundTripCase{4, false}, RoundTripCase{5, true}, RoundTripCase{6, true},
                      RoundTripCase{7, true}, RoundTripCase{8, true}),
    [](const auto& info) {
      return (info.param.partition ? "partition_seed" : "whole_seed") +
             std::to_string(info.param.seed);
    });

// A set restored from a snapshot with nothing uncommitted equals the original and goes on
// exactly like it under the same operations (locks unlock, holders release, ids continue).
TEST(SnapshotRestore, RestoredSetBehavesLikeTheOriginal) {
  for (std::uint64_t seed = 11; seed <= 14; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const auto conflicts = test::random_conflicts(seed, 10, 0.25);
    TimelineSet set(conflicts);
    TimelineWorkload workload(seed, conflicts, {}, /*queue=*/false);
    int settled = 0;
    for (int op = 0; op < 400 && settled < 3; ++op) {
      workload.apply(set);
      (void)set.expire(kForever - 1);  // every prepare expires: nothing held
      (void)set.take_grants();
      if (op < 100 || has_uncommitted(set)) continue;
      ++settled;
      auto restored = TimelineSet::restore(conflicts, {}, set.snapshot());
      ASSERT_TRUE(restored) << restored.error().message;
      ASSERT_TRUE(*restored == set) << "after operation " << op;
      TimelineSet original = set;
      TimelineWorkload same = workload;  // the same stream from here on
      TimelineWorkload twin = workload;
      for (int next = 0; next < 200; ++next) {
        const std::string did = same.apply(original);
        const std::string twin_did = twin.apply(*restored);
        ASSERT_EQ(did, twin_did);
        ASSERT_TRUE(*restored == original) << "diverged at " << did;
      }
    }
    EXPECT_EQ(settled, 3) << "the workload never settled";
  }
}

// Presumed abort: a prepared hold and a waiting request do not survive; the timelines they
// were on move to a new version; prepare ids are never reused.
TEST(SnapshotRestore, DropsPreparedHoldsAndWaitingRequests) {
  const std::vector<std::vector<EntityIndex>> conflicts{{1}, {0}, {}};
  TimelineSet set(conflicts);
  ASSERT_TRUE(set.reserve("amy", 1, {{0, {0, 10}}}));
  ASSERT_TRUE(set.reserve("bob", 2, {{0, {20, 30}}}));
  ASSERT_TRUE(set.allocate("amy", 0)->granted);
  const auto queued = set.allocate("bob", 0);
  ASSERT_TRUE(queued && !queued->granted);
  const auto held = set.prepare(set.expand("cat", 3, {{2, {5, 15}}}), {}, 1000);
  ASSERT_TRUE(held);
  const std::uint64_t version0 = set.version(0), version1 = set.version(1),
                      version2 = set.version(2);

  const TimelineSnapshot s = set.snapshot();
  auto restored = TimelineSet::restore(conflicts, {}, s);
  ASSERT_TRUE(restored) << restored.error().message;
  EXPECT_TRUE(restored->timeline(0).waiting.empty());
  EXPECT_TRUE(restored->timeline(2).reservations.empty());
  EXPECT_EQ(restored->timeline(0).holder, "amy");
  EXPECT_EQ(restored->version(0), version0 + 1);  // bob's request was dropped
  EXPECT_EQ(restored->version(1), version1);      // shadows only: unchanged
  EXPECT_EQ(restored->version(2), version2 + 1);  // cat's hold was dropped
  EXPECT_EQ(restored->commit(*held).error().code, ErrorCode::not_found);
  const auto again = restored->prepare(restored->expand("cat", 4, {{2, {5, 15}}}), {}, 1000);
  ASSERT_TRUE(again);
  EXPECT_GT(*again, *held);
  // bob asks again and learns the same place in the queue.
  const auto requeued = restored->allocate("bob", 0);
  ASSERT_TRUE(requeued);
  EXPECT_EQ(requeued->queue_position, queued->queue_position);
  EXPECT_FALSE(requeued->granted);
}

TEST(SnapshotRestore, PartialSnapshotLeavesTheRestEmpty) {
  const std::vector<std::vector<EntityIndex>> conflicts{{}, {}, {}};
  TimelineSet set(conflicts);
  ASSERT_TRUE(set.reserve("amy", 1, {{1, {0, 10}}}));
  ASSERT_TRUE(set.reserve("amy", 2, {{2, {0, 10}}}));
  auto restored = TimelineSet::restore(conflicts, {}, set.snapshot({1, 1, 5}));
  ASSERT_TRUE(restored) << restored.error().message;
  EXPECT_EQ(restored->timeline(1), set.timeline(1));
  EXPECT_EQ(restored->timeline(2), Timeline{});
  EXPECT_EQ(restored->timeline(0), Timeline{});
}

// ---- inconsistent snapshots ------------------------------------------------------------

/// A valid snapshot: entities 0 and 1 conflict. amy's route 1 goes 0 [0, 10) -> 2 [8, 20)
/// and she holds 0; bob's route 2 reserves 0 [20, 30); lock 1 on 3.
struct Base {
  std::vector<std::vector<EntityIndex>> conflicts{{1}, {0}, {}, {}};
  TimelineSnapshot snapshot;

  Base() {
    TimelineSet set(conflicts);
    EXPECT_TRUE(set.reserve("amy", 1, {{0, {0, 10}}, {2, {8, 20}}}));
    EXPECT_TRUE(set.reserve("bob", 2, {{0, {20, 30}}}));
    EXPECT_TRUE(set.allocate("amy", 0)->granted);
    EXPECT_TRUE(set.lock(3, {5, 15}, "op", "spill"));
    snapshot = set.snapshot();
  }
  EntitySnapshot& entity(EntityIndex e) {
    for (EntitySnapshot& es : snapshot.entities) {
      if (es.entity == e) return es;
    }
    throw std::logic_error("no entity " + std::to_string(e) + " in the base snapshot");
  }
  Reservation& item(EntityIndex e, const AgentId& agent) {
    for (Reservation& r : entity(e).reservations) {
      if (r.agent == agent) return r;
    }
    throw std::logic_error("no " + agent + " on " + std::to_string(e));
  }
};

struct BadCase {
  std::string name;
  std::function<void(Base&)> spoil;
  std::string message;  ///< a part of the expected error message
};

TEST(SnapshotRestore, BaseSnapshotIsAccepted) {
  Base base;
  ASSERT_EQ(base.snapshot.entities.size(), 4u);
  auto restored = TimelineSet::restore(base.conflicts, {}, base.snapshot);
  ASSERT_TRUE(restored) << restored.error().message;
  EXPECT_TRUE(restored->snapshot() == base.snapshot);
}

TEST(SnapshotRestore, RejectsInconsistentSnapshots) {
  const std::vector<BadCase> cases{
      {"counter 0", [](Base& b) { b.snapshot.next_lock_id = 0; }, "at least 1"},
      {"entity out of range", [](Base& b) { b.entity(3).entity = 9; }, "entity 9 is out of range"},
      {"entity twice", [](Base& b) { b.snapshot.entities.push_back(b.entity(2)); },
       "entity 2 is given twice"},
      {"overlap of two agents (I1)",
       [](Base& b) {
         b.item(0, "bob").window.start = 5;
         b.item(1, "bob").window.start = 5;
       },
       "entity 0: reservation bob/route 2/step 0 [5, 30) overlaps reservation amy"},
      {"prepared item", [](Base& b) { b.item(2, "amy").prepared = true; }, "entity 2: reservation amy/route 1/step 1 [8, 20): prepared"},
      {"empty agent", [](Base& b) { b.item(2, "amy").agent = ""; }, "entity 2: reservation /route 1/step 1 [8, 20): empty agent id"},
      {"reversed window", [](Base& b) { b.item(2, "amy").window = {20, 8}; }, "entity 2: reservation amy/route 1/step 1 [20, 8): empty or reversed window"},
      {"item on another timeline", [](Base& b) { b.item(2, "amy").entity = 3; }, "entity 2: reservation amy/route 1/step 1 (shadow of 2) [8, 20): names entity 3"},
      {"origin out of range", [](Base& b) { b.item(2, "amy").origin = 40; }, "origin 40 is out of range"},
      {"shadow of a non-conflicting entity",
       [](Base& b) { b.entity(2).reservations.push_back(Reservation{"cat", 5, 0, 2, 3, {40, 50}, false}); },
       "entity 2: reservation cat/route 5/step 0 (shadow of 3) [40, 50): entity 3 does not conflict"},
      {"step twice on a timeline",
       [](Base& b) { b.entity(2).reservations.push_back(Reservation{"amy", 1, 1, 2, 2, {30, 40}, false}); },
       "its route step is on this timeline twice"},
      {"real reservation without its shadow",
       [](Base& b) { std::erase_if(b.entity(1).reservations, [](const Reservation& r) { return r.agent == "bob"; }); },
       "entity 0: reservation bob/route 2/step 0 [20, 30) has no shadow with its window on entity 1"},
      {"shadow with another window", [](Base& b) { b.item(1, "bob").window.end = 31; },
       "entity 0: reservation bob/route 2/step 0 [20, 30) has no shadow with its window on entity 1"},
      {"shadow without its real reservation",
       [](Base& b) { b.entity(1).reservations.push_back(Reservation{"cat", 9, 0, 1, 0, {40, 50}, false}); },
       "entity 1: reservation cat/route 9/step 0 (shadow of 0) [40, 50) has no real reservation"},
      {"holder without its reservation", [](Base& b) { b.entity(0).holding->step.route = 7; },
       "entity 0: holder amy (route 7, step 0) has no real reservation of that step here"},
      {"holder with a shadow only", [](Base& b) { b.entity(1).holding = Holding{"amy", {1, 0}}; },
       "entity 1: holder amy (route 1, step 0) has no real reservation of that step here"},
      {"holder behind another agent (I2)", [](Base& b) { b.entity(0).holding = Holding{"bob", {2, 0}}; },
       "entity 0: holder bob (route 2, step 0) has reservation amy/route 1/step 0 [0, 10) before its own (I2)"},
      {"two agents hold conflicting entities",
       [](Base& b) {
         b.entity(1).reservations.push_back(Reservation{"bob", 3, 0, 1, 1, {40, 50}, false});
         b.entity(0).reservations.push_back(Reservation{"bob", 3, 0, 0, 1, {40, 50}, false});
         b.entity(1).holding = Holding{"bob", {3, 0}};
       },
       "entity 0: holder amy (route 1, step 0) and holder bob of conflicting entity 1"},
      {"empty holder", [](Base& b) { b.entity(0).holding->agent = ""; }, "entity 0: empty holder id"},
      {"lock id not below the counter", [](Base& b) { b.snapshot.next_lock_id = 1; },
       "entity 3: lock 1: the id is not in [1, next_lock_id 1)"},
      {"lock id used twice", [](Base& b) { b.entity(2).locks.push_back(Lock{1, 2, {0, 5}, "op", "x"}); },
       "lock 1: the id is used twice"},
      {"lock on another timeline", [](Base& b) { b.entity(3).locks[0].entity = 2; },
       "entity 3: lock 1: names entity 2"},
      {"lock with a reversed window", [](Base& b) { b.entity(3).locks[0].window = {5, 5}; },
       "entity 3: lock 1: empty or reversed window [5, 5)"},
      {"lock without operator", [](Base& b) { b.entity(3).locks[0].operator_id = ""; },
       "entity 3: lock 1: empty operator id"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.name);
    Base base;
    c.spoil(base);
    const auto restored = TimelineSet::restore(base.conflicts, {}, base.snapshot);
    ASSERT_FALSE(restored);
    EXPECT_EQ(restored.error().code, ErrorCode::invalid_argument);
    EXPECT_NE(restored.error().message.find(c.message), std::string::npos)
        << restored.error().message;
    EXPECT_EQ(restored.error().message.rfind("restore: ", 0), 0u) << restored.error().message;
  }
}

TEST(SnapshotRestore, RejectsEntitiesOutsideThePartition) {
  Base base;
  const auto restored = TimelineSet::restore(base.conflicts, {true, true, true, false}, base.snapshot);
  ASSERT_FALSE(restored);
  EXPECT_EQ(restored.error().message, "restore: entity 3 is not owned by this set");
}

}  // namespace
}  // namespace drover::topology
