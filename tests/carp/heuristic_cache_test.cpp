// The planner's cache of heuristic tables: goals asked for again (stations, replans) keep
// their tables however many goals are asked for once in between, and the tables a request
// holds are never replaced during it.

#include <memory>

#include <gtest/gtest.h>

#include "carp/src/heuristic.hpp"
#include "grid_builder.hpp"

namespace drover::carp::test {
namespace {

constexpr std::uint64_t kClass = 1;

class HeuristicCacheTest : public ::testing::Test {
 protected:
  HeuristicCacheTest() {
    GridBuilder g;
    for (int x = 0; x < kCells; ++x) g.cell(x, 0);
    for (int x = 0; x + 1 < kCells; ++x) g.edge(x, 0, x + 1, 0);
    topology_ = std::make_unique<topology::Topology>(std::move(g).build());
    graph_ = std::make_unique<RoutingGraph>(*topology_);
  }
  /// The table for goal cell `x`, asked for by a request of its own.
  HeuristicTable* ask(HeuristicCache& cache, int x) {
    cache.next_request();
    return &cache.table(*graph_, kClass, vertex(x));
  }
  topology::EntityIndex vertex(int x) const { return *topology_->find(cell_id(x, 0)); }

  static constexpr int kCells = 40;
  std::unique_ptr<topology::Topology> topology_;
  std::unique_ptr<RoutingGraph> graph_;
};

TEST_F(HeuristicCacheTest, AGoalAskedForTwiceKeepsItsTableThroughAStreamOfOneOffGoals) {
  HeuristicCache cache(4);
  HeuristicTable* station = ask(cache, 0);
  ASSERT_EQ(ask(cache, 0), station);  // the second request protects it
  for (int x = 1; x < kCells; ++x) ask(cache, x);  // goals asked for once each
  EXPECT_EQ(station->root(), vertex(0));
  EXPECT_EQ(ask(cache, 0), station);
}

TEST_F(HeuristicCacheTest, AGoalAskedForAgainAfterItsTableWasReplacedIsKeptFromThen) {
  HeuristicCache cache(2);
  ask(cache, 0);
  ask(cache, 1);
  ask(cache, 2);  // full: replaces the table of goal 1, on probation and used last
  HeuristicTable* replan = ask(cache, 1);  // asked for again: back, and protected
  EXPECT_EQ(replan->root(), vertex(1));
  for (int x = 3; x < kCells; ++x) ask(cache, x);
  EXPECT_EQ(replan->root(), vertex(1));
  EXPECT_EQ(ask(cache, 1), replan);
}

TEST_F(HeuristicCacheTest, TablesHeldByTheRequestAreNotReplacedDuringIt) {
  HeuristicCache cache(1);
  cache.next_request();  // one request with three stops
  HeuristicTable* first = &cache.table(*graph_, kClass, vertex(5));
  HeuristicTable* second = &cache.table(*graph_, kClass, vertex(6));
  HeuristicTable* third = &cache.table(*graph_, kClass, vertex(7));
  EXPECT_EQ(first->root(), vertex(5));
  EXPECT_EQ(second->root(), vertex(6));
  EXPECT_EQ(third->root(), vertex(7));
  EXPECT_NE(first, second);
  EXPECT_NE(second, third);
}

TEST_F(HeuristicCacheTest, AKeptTableAnswersAsANewOne) {
  HeuristicCache cache(2);
  const Traversal traversal(*graph_, VehicleProfile{.id = "v", .type = "agv", .max_speed = 1.0,
                                                   .length = 1.0, .width = 1.0});
  HeuristicTable* table = ask(cache, 10);
  EXPECT_EQ(table->distance(*graph_, traversal, vertex(13)), 3 * kNsPerSecond);
  for (int x = 20; x < 30; ++x) ask(cache, x);  // replaces the table: asked for once
  HeuristicTable* again = ask(cache, 10);
  EXPECT_EQ(again->root(), vertex(10));
  EXPECT_EQ(again->distance(*graph_, traversal, vertex(4)), 6 * kNsPerSecond);
  EXPECT_EQ(again->distance(*graph_, traversal, vertex(13)), 3 * kNsPerSecond);
}

}  // namespace
}  // namespace drover::carp::test
