#pragma once
// The planner's heuristic: the exact reservation-free travel time from any vertex to a goal,
// computed by a backward A* from the goal that is resumed on demand (Silver's reverse
// resumable A*) and kept between calls for the same goal and vehicle class.

#include <cstdint>
#include <memory>
#include <vector>

#include "min_heap.hpp"
#include "traversal.hpp"

namespace drover::carp {

class HeuristicTable {
 public:
  /// Starts over for `goal` (reusing the memory).
  void reset(const RoutingGraph& graph, topology::EntityIndex goal);
  topology::EntityIndex goal() const noexcept { return goal_; }

  /// Guides the search towards `target` (the vertex the next queries come from). Any target
  /// gives exact distances; a near one makes them cheap.
  void aim(const RoutingGraph& graph, const Traversal& traversal, topology::EntityIndex target);

  /// The reservation-free travel time from `vertex` to the goal for the traversal's class,
  /// or kUnreachable. Exact, hence admissible and consistent as an A* heuristic.
  DurationNs distance(const RoutingGraph& graph, const Traversal& traversal,
                      topology::EntityIndex vertex) {
    return closed_[vertex] ? distance_[vertex] : resume(graph, traversal, vertex);
  }

 private:
  struct Entry {
    DurationNs key;  // distance + lower bound to the target
    DurationNs distance;
    topology::EntityIndex vertex;
    bool operator>(const Entry& other) const { return key > other.key; }
  };
  DurationNs resume(const RoutingGraph& graph, const Traversal& traversal,
                    topology::EntityIndex vertex);

  topology::EntityIndex goal_ = topology::kNoEntity;
  topology::EntityIndex target_ = topology::kNoEntity;
  std::vector<DurationNs> distance_;
  std::vector<std::uint8_t> closed_;
  MinHeap<Entry> open_;
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
