// The planner's distance tables (the heuristic, and the floor proofs' times from the start)
// against an independent search: on random grids whose arcs take uneven times (real
// lengths, several speed limits, one-way edges), or all the same time (the breadth-first
// search), and whose cells and edges the vehicle may not all use (its type forbidden
// there), the distance to or from the root they give every vertex is FreePathSearch's
// fastest travel time, whatever order the vertices are asked in (a table resumes its
// search on demand, over the traversal's flat adjacency).

#include <algorithm>
#include <array>
#include <random>

#include <gtest/gtest.h>

#include "carp/src/heuristic.hpp"
#include "drover/carp/free_path.hpp"
#include "grid_builder.hpp"
#include "route_checks.hpp"

namespace drover::carp::test {
namespace {

/// `uniform`: every edge 1 m long at 1 m/s, so every arc takes one second. Sides of
/// `min_side` to `max_side` cells.
topology::Topology random_grid(std::mt19937& rng, bool uniform, int min_side = 2,
                               int max_side = 8) {
  std::uniform_real_distribution<double> coin(0, 1), length(0.3, 4.0);
  const int width = std::uniform_int_distribution<int>(min_side, max_side)(rng);
  const int height = std::uniform_int_distribution<int>(min_side, max_side)(rng);
  GridBuilder g;
  const auto maybe_forbidden = [&] {
    topology::Restrictions restrictions;
    if (coin(rng) < 0.08) restrictions.forbidden_vehicle_types = {"agv"};
    return restrictions;
  };
  for (int x = 0; x < width; ++x) {
    for (int y = 0; y < height; ++y) g.cell(x, y, maybe_forbidden());
  }
  const auto maybe_edge = [&](int x1, int y1, int x2, int y2) {
    if (x2 >= width || y2 >= height || coin(rng) < 0.15) return;
    EdgeOptions options;
    options.length = uniform ? 1.0 : length(rng);
    options.max_speed =
        uniform ? 1.0 : std::array{0.5, 1.0, 1.7}[std::uniform_int_distribution<int>(0, 2)(rng)];
    options.bidirectional = coin(rng) < 0.8;
    options.restrictions = maybe_forbidden();
    if (!options.bidirectional && coin(rng) < 0.5) {
      std::swap(x1, x2);
      std::swap(y1, y2);
    }
    g.edge(x1, y1, x2, y2, options);
  };
  for (int x = 0; x < width; ++x) {
    for (int y = 0; y < height; ++y) {
      maybe_edge(x, y, x + 1, y);
      maybe_edge(x, y, x, y + 1);
    }
  }
  return std::move(g).build();
}

TEST(DistanceTable, GivesTheFastestTravelTimeBetweenTheRootAndEveryVertex) {
  std::mt19937 rng(11);
  const VehicleProfile vehicle = unit_vehicle();
  int compared = 0;
  for (int trial = 0; trial < 120; ++trial) {
    const bool uniform = trial % 2 == 1;
    const auto topology = random_grid(rng, uniform);
    const auto graph = std::make_shared<RoutingGraph>(topology);
    const Traversal traversal(*graph, vehicle);
    // The uneven grids' lengths are drawn from a continuum: never all equal.
    ASSERT_EQ(traversal.uniform(), uniform) << "trial " << trial;
    FreePathSearch reference(graph);
    const std::size_t n = graph->vertex_count();
    std::vector<topology::EntityIndex> order(n);
    for (std::size_t v = 0; v < n; ++v) order[v] = static_cast<topology::EntityIndex>(v);
    HeuristicTable to_table;  // each reused, as the cache and the search do
    ReachTable from_table;
    for (int root_trial = 0; root_trial < 6; ++root_trial) {
      // A root the vehicle may use, as the planner's (it checks starts and stops first).
      auto root = static_cast<topology::EntityIndex>(rng() % n);
      for (std::size_t tries = 0; tries < n && !traversal.usable_vertex(root); ++tries) {
        root = static_cast<topology::EntityIndex>((root + 1) % n);
      }
      if (!traversal.usable_vertex(root)) continue;
      const bool to_root = root_trial % 2 == 0;
      // Each table's first and third roots are asked about a few vertices only (none, or a
      // search stopped early): resets follow partly and wholly searched tables.
      const std::size_t asked = root_trial % 4 < 2 ? std::min<std::size_t>(rng() % 4, n) : n;
      if (to_root) {
        to_table.reset(*graph, root);
      } else {
        from_table.reset(*graph, root);
      }
      std::shuffle(order.begin(), order.end(), rng);
      for (std::size_t k = 0; k < asked; ++k) {
        const auto v = order[k];
        const auto path = to_root ? reference.find(vehicle, v, root) : reference.find(vehicle, root, v);
        const DurationNs expected = path ? path->travel_time : kUnreachable;
        const DurationNs found = to_root ? to_table.distance(*graph, traversal, v)
                                         : from_table.distance(*graph, traversal, v);
        ASSERT_EQ(found, expected) << "trial " << trial << ": " << topology.id(v)
                                   << (to_root ? " to " : " from ") << topology.id(root);
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 3000);
}

// A vertex with more arcs than Traversal::Adjacency::kMaxPaddedDegree: the small tables'
// loop then runs over each vertex's own arcs, unpadded; the same distances.
TEST(DistanceTable, GivesTheFastestTravelTimesAroundAHubOfManyArcs) {
  GridBuilder g;
  g.corridor(12);  // (0,0) .. (11,0), joined in a row
  g.cell(5, 3);    // the hub, joined to every cell of the row but (11,0), one way to (0,0)
  for (int x = 1; x < 11; ++x) g.edge(5, 3, x, 0);
  EdgeOptions one_way;
  one_way.bidirectional = false;
  g.edge(0, 0, 5, 3, one_way);
  const auto topology = g.build();
  const auto graph = std::make_shared<RoutingGraph>(topology);
  const VehicleProfile vehicle = unit_vehicle();
  const Traversal traversal(*graph, vehicle);
  ASSERT_EQ(traversal.adjacency(*graph).padded_degree, 0u);
  FreePathSearch reference(graph);
  HeuristicTable to_table;
  ReachTable from_table;
  for (topology::EntityIndex root = 0; root < graph->vertex_count(); ++root) {
    to_table.reset(*graph, root);
    from_table.reset(*graph, root);
    for (topology::EntityIndex v = 0; v < graph->vertex_count(); ++v) {
      const auto to = reference.find(vehicle, v, root);
      const auto from = reference.find(vehicle, root, v);
      ASSERT_EQ(to_table.distance(*graph, traversal, v), to ? to->travel_time : kUnreachable)
          << topology.id(v) << " to " << topology.id(root);
      ASSERT_EQ(from_table.distance(*graph, traversal, v),
                from ? from->travel_time : kUnreachable)
          << topology.id(root) << " to " << topology.id(v);
    }
  }
}

// Breadth-first tables too large for L1 take a loop of their own (with a branch): the same
// distances there, asked in random order, the search resumed and reset.
TEST(DistanceTable, GivesTheFastestTravelTimesOnLargeUniformGridsToo) {
  std::mt19937 rng(12);
  const VehicleProfile vehicle = unit_vehicle();
  for (int trial = 0; trial < 3; ++trial) {
    const auto topology = random_grid(rng, true, 45, 50);
    const auto graph = std::make_shared<RoutingGraph>(topology);
    ASSERT_GT(graph->vertex_count() * sizeof(DurationNs), HeuristicTable::kBranchlessBytes);
    const Traversal traversal(*graph, vehicle);
    FreePathSearch reference(graph);
    HeuristicTable table;
    for (int root_trial = 0; root_trial < 2; ++root_trial) {
      auto root = static_cast<topology::EntityIndex>(rng() % graph->vertex_count());
      while (!traversal.usable_vertex(root)) root = (root + 1) % graph->vertex_count();
      table.reset(*graph, root);
      for (int k = 0; k < 150; ++k) {
        const auto v = static_cast<topology::EntityIndex>(rng() % graph->vertex_count());
        const auto path = reference.find(vehicle, v, root);
        ASSERT_EQ(table.distance(*graph, traversal, v), path ? path->travel_time : kUnreachable)
            << "trial " << trial << ": " << topology.id(v) << " to " << topology.id(root);
      }
    }
  }
}

}  // namespace
}  // namespace drover::carp::test
