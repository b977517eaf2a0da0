#include "heuristic.hpp"

#include <algorithm>
#include <utility>

namespace drover::carp {

using topology::EntityIndex;

template <Direction kDirection>
void DistanceTable<kDirection>::reset(const RoutingGraph& graph, EntityIndex root) {
  if (label_.size() != graph.vertex_count() + 1 || (queued_root_ && fifo_tail_ == 0)) {
    // New, or after a Dijkstra search. The last label, the padding's (see
    // Traversal::Adjacency::padded_degree), stays closed.
    label_.assign(graph.vertex_count() + 1, kUnreachable);
    label_.back() = ~DurationNs{0};
  } else if (!queued_root_) {
    label_[root_] = kUnreachable;  // never searched: only the root was set
  } else {
    // Breadth-first, every vertex labelled was queued: clearing those costs a fraction of a
    // fill on a search that stopped early, and leaves the rest of the table alone in cache.
    for (std::size_t i = 0; i < fifo_tail_; ++i) label_[fifo_[i]] = kUnreachable;
  }
  root_ = root;
  open_.clear();
  fifo_head_ = 0;
  fifo_tail_ = 0;
  label_[root] = 0;
  queued_root_ = false;  // the first resume queues it, knowing the traversal
}

template <Direction kDirection>
DurationNs DistanceTable<kDirection>::resume(const RoutingGraph& graph,
                                             const Traversal& traversal, EntityIndex vertex) {
  if (traversal.uniform()) return breadth_first(graph, traversal, vertex);
  // Keys are distances in units of the shortest arc's travel time, rounded down (Dinitz):
  // whatever the order among equal keys, a vertex's distance is final when it is popped,
  // since every arc into it comes from a vertex with a smaller key, popped before.
  const DurationNs unit = traversal.min_travel();
  const auto relax = [&](EntityIndex next, DurationNs through) {
    if (through >= label_[next]) return;  // closed, or no better
    label_[next] = through;
    open_.push(static_cast<std::uint64_t>(through / unit), next);
  };
  if (!queued_root_) {
    queued_root_ = true;
    open_.push(0, root_);
  }
  const Traversal::Adjacency& adjacency = traversal.adjacency(graph);
  while (!open_.empty()) {
    const EntityIndex top = open_.pop().value;
    const DurationNs distance = label_[top];
    if (distance < 0) continue;  // stale: popped before
    label_[top] = ~distance;
    if constexpr (kDirection == Direction::to_root) {
      // Backwards: the arcs into top lead from the vertices that can reach it.
      for (const Traversal::Hop& hop : adjacency.into_of(top)) {
        relax(hop.from, distance + adjacency.timing(hop).travel);
      }
    } else {  // a root the vehicle may not use leads nowhere (it has no moves)
      for (const Traversal::Move& move : adjacency.out_of(top)) {
        relax(move.to, distance + adjacency.timing(move).travel);
      }
    }
    if (top == vertex) return distance;
  }
  return kUnreachable;  // every vertex connected with the root is closed, and `vertex` is not
}

namespace {

/// stored = old if old is negative (a closed label), by a conditional move: GCC 12 makes a
/// branch of every way of writing this in C++ but mask arithmetic (more instructions).
[[gnu::always_inline]] inline void keep_if_closed(DurationNs& stored, DurationNs old) {
#if defined(__x86_64__)
  asm("testq %[old], %[old]\n\tcmovsq %[old], %[stored]"
      : [stored] "+r"(stored)
      : [old] "r"(old)
      : "cc");
#else
  stored = old < 0 ? old : stored;
#endif
}

/// Labels `v` found at `found` (~distance) and queues it, unless it was found before: then
/// it keeps its label, at its shortest, and the queue slot written stays free. Every label
/// is closed (negative) or kUnreachable (not found yet, positive): the sign alone says
/// whether a vertex was found.
/// kBranchless (see DistanceTable::kBranchlessBytes): whether a neighbour was found is a
/// coin toss, and with every label in L1 a misprediction costs more than the stores.
/// Otherwise a branch around the label's store and the tail's step (GCC 12's choice), which
/// suits the warehouse's aisles, where it predicts well and lets the cache misses of later
/// labels overlap.
template <bool kBranchless>
[[gnu::always_inline]] inline void find(DurationNs* label, EntityIndex* queue, std::size_t& tail,
                                        DurationNs found, EntityIndex v) {
  const DurationNs old = label[v];
  if constexpr (kBranchless) {
    DurationNs stored = found;
    keep_if_closed(stored, old);
    label[v] = stored;
    queue[tail] = v;
    tail += 1 + (old >> 63);  // 0 if found (old >> 63 is -1 for a negative label)
  } else {
    const bool was_found = old < 0;
    label[v] = was_found ? old : found;
    queue[tail] = v;
    tail += was_found ? 0 : 1;
  }
}

/// Follows the arcs of the vertices in `queue[head, tail)`, breadth-first, until `vertex`
/// is closed or the queue runs out. `lists` holds each vertex's neighbours, padded to
/// kDegree entries (Traversal::Adjacency::padded_degree): with the degree known to the
/// compiler the neighbours are visited without a loop. Bench plan, against the degree read
/// at run time: planner instructions -3.0 % at random N = 200, -3.2 % at N = 400, -4.4 % at
/// warehouse N = 400; in-process A/B over 30 repeats, two runs: ratio to A* -1 to -3 %,
/// -0.5 to -2 %, -2 to -6 %.
template <std::size_t kDegree, bool kBranchless>
void close_padded(const EntityIndex* lists, DurationNs* label, EntityIndex* queue,
                  std::size_t& head, std::size_t& tail, DurationNs unit, EntityIndex vertex) {
  while (label[vertex] >= 0 && head < tail) {
    const EntityIndex top = queue[head++];
    const DurationNs found = ~(~label[top] + unit);
    const EntityIndex* next = lists + std::size_t{top} * kDegree;
    [&]<std::size_t... k>(std::index_sequence<k...>) {
      (find<kBranchless>(label, queue, tail, found, next[k]), ...);
    }(std::make_index_sequence<kDegree>{});
  }
}

/// close_padded for any degree, the neighbours read from the adjacency's lists of the
/// table's direction (padded where kBranchless and the adjacency has them, so that the loop
/// runs as often for every vertex).
template <Direction kDirection, bool kBranchless>
void close_any(const Traversal::Adjacency& adjacency, DurationNs* label, EntityIndex* queue,
               std::size_t& head, std::size_t& tail, DurationNs unit, EntityIndex vertex) {
  const bool padded = kBranchless && adjacency.padded_degree > 0;
  while (label[vertex] >= 0 && head < tail) {
    const EntityIndex top = queue[head++];
    const DurationNs found = ~(~label[top] + unit);
    // Backwards to the root (the vertices that can reach top), or onwards from it.
    const std::span<const EntityIndex> next =
        kDirection == Direction::to_root
            ? (padded ? adjacency.padded_sources_of(top) : adjacency.sources_of(top))
            : (padded ? adjacency.padded_targets_of(top) : adjacency.targets_of(top));
    for (const EntityIndex v : next) find<kBranchless>(label, queue, tail, found, v);
  }
}

}  // namespace

// When every arc takes the same time, a first-in first-out queue holds the vertices in order
// of distance, so a vertex's first distance is its shortest: it is closed (~distance) as soon
// as it is found, and distance() answers it inline from then on. No keys, no division, each
// vertex queued once, and only the vertex ids of the arcs read.
template <Direction kDirection>
DurationNs DistanceTable<kDirection>::breadth_first(const RoutingGraph& graph,
                                                    const Traversal& traversal,
                                                    EntityIndex vertex) {
  if (!queued_root_) {
    queued_root_ = true;
    // Each vertex is queued once; one slot more, which the loop below writes past the tail.
    if (fifo_.size() <= graph.vertex_count()) fifo_.resize(graph.vertex_count() + 1);
    fifo_[fifo_tail_++] = root_;
    label_[root_] = ~DurationNs{0};
  }
  const Traversal::Adjacency& adjacency = traversal.adjacency(graph);
  const DurationNs unit = traversal.min_travel();
  EntityIndex* const queue = fifo_.data();
  DurationNs* const label = label_.data();
  // In locals: the label stores could alias the members (same type, but for the sign).
  std::size_t head = fifo_head_, tail = fifo_tail_;
  const bool small = graph.vertex_count() * sizeof(DurationNs) <= kBranchlessBytes;
  const EntityIndex* const lists = kDirection == Direction::to_root
                                       ? adjacency.padded_into_from.data()
                                       : adjacency.padded_out_to.data();
  // The degrees of grids (4 or 8 neighbours) unrolled; other graphs loop.
  switch (adjacency.padded_degree) {
    case 4:
      small ? close_padded<4, true>(lists, label, queue, head, tail, unit, vertex)
            : close_padded<4, false>(lists, label, queue, head, tail, unit, vertex);
      break;
    case 8:
      small ? close_padded<8, true>(lists, label, queue, head, tail, unit, vertex)
            : close_padded<8, false>(lists, label, queue, head, tail, unit, vertex);
      break;
    default:
      small ? close_any<kDirection, true>(adjacency, label, queue, head, tail, unit, vertex)
          : close_any<kDirection, false>(adjacency, label, queue, head, tail, unit, vertex);
  }
  fifo_head_ = head;
  fifo_tail_ = tail;
  // Not found once every vertex connected with the root is.
  return label[vertex] < 0 ? ~label[vertex] : kUnreachable;
}

template class DistanceTable<Direction::to_root>;
template class DistanceTable<Direction::from_root>;

HeuristicTable& HeuristicCache::table(const RoutingGraph& graph, std::uint64_t class_id,
                                      EntityIndex goal) {
  for (Entry& entry : entries_) {
    if (entry.class_id == class_id && entry.goal == goal) {
      entry.kept = entry.kept || entry.last_request != request_;  // a second request
      entry.last_request = request_;
      return *entry.table;
    }
  }
  const bool kept = recall(class_id, goal);
  Entry* slot = entries_.size() < capacity_ ? nullptr : victim();
  if (slot == nullptr) {
    entries_.push_back(Entry{std::make_unique<HeuristicTable>()});
    slot = &entries_.back();
  } else if (!slot->kept) {
    // Remember the pair replaced on probation, in a ring of capacity_ pairs.
    const Pair pair{slot->class_id, slot->goal};
    if (replaced_.size() < capacity_) {
      replaced_.push_back(pair);
    } else {
      replaced_[replaced_next_] = pair;
      replaced_next_ = (replaced_next_ + 1) % capacity_;
    }
  }
  slot->goal = goal;
  slot->class_id = class_id;
  slot->last_request = request_;
  slot->kept = kept;
  slot->table->reset(graph, goal);
  return *slot->table;
}

HeuristicCache::Entry* HeuristicCache::victim() {
  Entry* newest_on_probation = nullptr;
  Entry* oldest_kept = nullptr;
  for (Entry& entry : entries_) {
    if (entry.last_request == request_) continue;  // held by this request
    if (!entry.kept) {
      if (newest_on_probation == nullptr ||
          entry.last_request > newest_on_probation->last_request) {
        newest_on_probation = &entry;
      }
    } else if (oldest_kept == nullptr || entry.last_request < oldest_kept->last_request) {
      oldest_kept = &entry;
    }
  }
  return newest_on_probation != nullptr ? newest_on_probation : oldest_kept;
}

bool HeuristicCache::recall(std::uint64_t class_id, EntityIndex goal) {
  for (Pair& pair : replaced_) {
    if (pair.class_id == class_id && pair.goal == goal) {
      pair.goal = topology::kNoEntity;  // forgotten: back in the cache from now on
      return true;
    }
  }
  return false;
}

}  // namespace drover::carp
