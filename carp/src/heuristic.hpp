#pragma once
// The planner's heuristic: the exact reservation-free travel time from any vertex to a goal,
// computed by a backward Dijkstra search from the goal that is resumed on demand (as in
// Silver's reverse resumable A*, without the aim) and kept between calls for the same goal
// and vehicle class.
//
// Why not aimed at the start with the straight-line bound (A* order), as it was: on
// grid-like maps that bound is weak around obstacles, and the planner asks for the vertices
// around the start and its detours, which an aimed search reaches only by resuming through
// its ellipse. Without the aim the keys are plain distances, monotone, so a radix heap
// serves instead of a binary heap and no bound is computed per push: bench plan on
// random-32-32-20, N = 50, closes 22 100 vertices instead of 11 600, yet the planner runs
// 4 % fewer instructions in all (docs/benchmarks.md).

#include <cstdint>
#include <memory>
#include <vector>

#include "radix_heap.hpp"
#include "traversal.hpp"

namespace drover::carp {

class HeuristicTable {
 public:
  /// Starts over for `goal` (reusing the memory).
  void reset(const RoutingGraph& graph, topology::EntityIndex goal);
  topology::EntityIndex goal() const noexcept { return goal_; }

  /// The reservation-free travel time from `vertex` to the goal for the traversal's class,
  /// or kUnreachable. Exact, hence admissible and consistent as an A* heuristic. Closes the
  /// vertices nearer to the goal first, so asking for a near vertex is cheap.
  DurationNs distance(const RoutingGraph& graph, const Traversal& traversal,
                      topology::EntityIndex vertex) {
    return closed_[vertex] ? distance_[vertex] : resume(graph, traversal, vertex);
  }

 private:
  DurationNs resume(const RoutingGraph& graph, const Traversal& traversal,
                    topology::EntityIndex vertex);

  topology::EntityIndex goal_ = topology::kNoEntity;
  std::vector<DurationNs> distance_;
  std::vector<std::uint8_t> closed_;
  RadixHeap<topology::EntityIndex> open_;  // keyed by distance; stale entries are skipped
};

/// The heuristic tables of the latest (vehicle class, goal) pairs, least recently used
/// replaced first. Tables handed out during one request stay valid until the next request.
class HeuristicCache {
 public:
  explicit HeuristicCache(std::size_t capacity) : capacity_(capacity < 1 ? 1 : capacity) {}

  /// Marks the start of a request: tables handed out before may now be replaced.
  void next_request() noexcept { ++request_; }
  HeuristicTable& table(const RoutingGraph& graph, std::uint64_t class_id,
                        topology::EntityIndex goal);

 private:
  struct Entry {
    std::unique_ptr<HeuristicTable> table;
    std::uint64_t class_id = 0;
    std::uint64_t last_request = 0;
  };
  std::size_t capacity_;
  std::vector<Entry> entries_;
  std::uint64_t request_ = 1;
};

}  // namespace drover::carp
