#pragma once
// The planner's heuristic: the exact reservation-free travel time from any vertex to a goal,
// computed by a backward Dijkstra search from the goal that is resumed on demand (as in
// Silver's reverse resumable A*, without the aim) and kept between calls for the same goal
// and vehicle class. The same tables, run forwards from a search's start, give the floor
// proofs the earliest time the vehicle can reach a vertex.
//
// Why not aimed at the start with the straight-line bound (A* order), as it was: on
// grid-like maps that bound is weak around obstacles, and the planner asks for the vertices
// around the start and its detours, which an aimed search reaches only by resuming through
// its ellipse. Without the aim the keys are plain distances, monotone, so a radix heap
// serves instead of a binary heap and no bound is computed per push: bench plan on
// random-32-32-20, N = 50, closes 22 100 vertices instead of 11 600, yet the planner runs
// 4 % fewer instructions in all (docs/benchmarks.md). Where every arc takes the same time
// (grids with one speed, as the benchmark's), the search is breadth-first on a plain queue:
// the planner runs 7 to 13 % fewer instructions there than with the radix heap; closing each
// vertex when it is first found, and reading only the vertex ids of the arcs, 5 to 11 % fewer
// again.

#include <cstdint>
#include <memory>
#include <vector>

#include "radix_heap.hpp"
#include "traversal.hpp"

namespace drover::carp {

/// Which way a DistanceTable measures.
enum class Direction {
  to_root,    ///< from each vertex to the root: the heuristic, the root being a goal
  from_root,  ///< from the root to each vertex: the earliest a vehicle gets there
};

/// Exact reservation-free travel times between a root vertex and every vertex, in one
/// direction, for one traversal (vehicle class), found on demand. The direction is a
/// template parameter: a test of it inside the search loop cost the planner 10 % more
/// instructions (bench plan, random-32-32-20, N = 50).
template <Direction kDirection>
class DistanceTable {
 public:
  /// Starts over for `root` (reusing the memory). \pre the vehicle class may use `root`
  /// (the planner checks starts and stops first); its distance is 0 all the same.
  void reset(const RoutingGraph& graph, topology::EntityIndex root);
  topology::EntityIndex root() const noexcept { return root_; }

  /// Breadth-first tables whose labels take up to this many bytes search without a branch:
  /// well within a small L1 data cache (32 KiB), so that the labels stay there. Bench plan
  /// on random-32-32-20 (819 vertices, 6.5 KiB of labels), ten alternating runs: ratio to
  /// A* 3.52 -> 3.36 at N = 200, 3.51 -> 3.18 at N = 400. warehouse-10-20-10-2-1 (5 699
  /// vertices, 45 KiB) keeps the branch, which was faster there. The branchless loop reads
  /// the padded arc lists (Traversal::Adjacency::padded_degree), so that it runs as often
  /// for every vertex; the table has one label more, the padding's, which stays closed.
  static constexpr std::size_t kBranchlessBytes = 12 * 1024;

  /// The reservation-free travel time between `vertex` and the root (in the table's
  /// direction) for the traversal's class, or kUnreachable. Exact, hence admissible and
  /// consistent as an A* heuristic. Closes the vertices nearer to the root first, so asking
  /// for a near vertex is cheap. \pre the same traversal since reset
  DurationNs distance(const RoutingGraph& graph, const Traversal& traversal,
                      topology::EntityIndex vertex) {
    const DurationNs label = label_[vertex];
    return label < 0 ? ~label : resume(graph, traversal, vertex);
  }

 private:
  DurationNs resume(const RoutingGraph& graph, const Traversal& traversal,
                    topology::EntityIndex vertex);
  /// resume() where every arc takes the same time.
  DurationNs breadth_first(const RoutingGraph& graph, const Traversal& traversal,
                           topology::EntityIndex vertex);

  topology::EntityIndex root_ = topology::kNoEntity;
  // Per vertex: the best distance found, kUnreachable if none, or ~distance (< 0) once the
  // vertex is closed; one array, so that a relaxation's test of both is one load (a closed
  // label is below every distance).
  std::vector<DurationNs> label_;
  RadixHeap<topology::EntityIndex> open_;  // keyed by distance; stale entries are skipped
  // Instead of open_ when every arc takes the same time: the vertices found, in order of
  // distance (fifo_tail_ of them); the first fifo_head_ have had their arcs followed.
  std::vector<topology::EntityIndex> fifo_;
  std::size_t fifo_head_ = 0, fifo_tail_ = 0;
  bool queued_root_ = false;  // the root waits in the queue the traversal calls for
};

/// Distances to a goal: the planner's heuristic.
using HeuristicTable = DistanceTable<Direction::to_root>;
/// Distances from a search's start: how early a route can be anywhere.
using ReachTable = DistanceTable<Direction::from_root>;

extern template class DistanceTable<Direction::to_root>;
extern template class DistanceTable<Direction::from_root>;

/// The heuristic tables (distances to a goal) of recent (vehicle class, goal) pairs, kept so
/// that goals asked for again (stations, a vehicle's replans) cost no search. Scan
/// resistant, in the manner of 2Q (Johnson and Shasha): a table asked for by one request
/// only is on probation; a second request for its pair protects it. When full, the cache
/// replaces the table on probation used last, else the protected one used least recently,
/// never one the current request holds. So a stream of goals asked for once (pick
/// locations) turns over one table, and the protected ones stay; and the table turned over
/// is the one the last such goal used, still in cache (bench plan, warehouse N = 200 and
/// 400: about 5 % less planner time than replacing the least recently used, whose memory
/// was cold).
/// A pair replaced while on probation is remembered (up to capacity pairs): asked for
/// again, it comes back protected, so a goal asked for twice with others in between is
/// kept from then on. Tables handed out during one request stay valid until the next.
class HeuristicCache {
 public:
  explicit HeuristicCache(std::size_t capacity) : capacity_(capacity < 1 ? 1 : capacity) {}

  /// Marks the start of a request: tables handed out before may now be replaced.
  void next_request() noexcept { ++request_; }
  /// The table of (class_id, goal), set up for `goal` if it was not kept (reset: its
  /// distances are found on demand).
  HeuristicTable& table(const RoutingGraph& graph, std::uint64_t class_id,
                        topology::EntityIndex goal);

 private:
  struct Entry {
    std::unique_ptr<HeuristicTable> table;
    /// The table's root, kept here too: a lookup compares every entry, and reading it from
    /// the table would touch as many tables.
    topology::EntityIndex goal = topology::kNoEntity;
    std::uint64_t class_id = 0;
    std::uint64_t last_request = 0;
    bool kept = false;  ///< protected: asked for by a second request
  };
  struct Pair {
    std::uint64_t class_id;
    topology::EntityIndex goal;
  };
  /// The entry to replace: see the class comment. nullptr if the request holds them all.
  Entry* victim();
  /// Whether (class_id, goal) was replaced on probation lately; forgets it if so.
  bool recall(std::uint64_t class_id, topology::EntityIndex goal);

  std::size_t capacity_;
  std::vector<Entry> entries_;
  std::vector<Pair> replaced_;  ///< ring of pairs replaced on probation (see recall)
  std::size_t replaced_next_ = 0;
  std::uint64_t request_ = 1;
};

}  // namespace drover::carp
