#include "heuristic.hpp"

#include <algorithm>

namespace drover::carp {

using topology::EntityIndex;

template <Direction kDirection>
void DistanceTable<kDirection>::reset(const RoutingGraph& graph, EntityIndex root) {
  root_ = root;
  label_.assign(graph.vertex_count(), kUnreachable);
  open_.clear();
  fifo_.clear();
  fifo_head_ = 0;
  label_[root] = 0;
  queued_root_ = false;  // the first resume queues it, knowing the traversal
}

template <Direction kDirection>
DurationNs DistanceTable<kDirection>::resume(const RoutingGraph& graph,
                                             const Traversal& traversal, EntityIndex vertex) {
  // Keys are distances in units of the shortest arc's travel time, rounded down (Dinitz):
  // whatever the order among equal keys, a vertex's distance is final when it is popped,
  // since every arc into it comes from a vertex with a smaller key, popped before. When
  // every arc takes the same time, a first-in first-out queue pops in order of distance
  // (breadth-first search): no keys, no division, each vertex queued once.
  const bool breadth_first = traversal.uniform();
  // Breadth-first, a vertex's first distance is its shortest: no need to wait for its pop.
  if (breadth_first && label_[vertex] != kUnreachable) return label_[vertex];
  const DurationNs unit = traversal.min_travel();
  const auto queue = [&](EntityIndex next, DurationNs through) {
    if (breadth_first) {
      fifo_.push_back(next);
    } else {
      open_.push(static_cast<std::uint64_t>(through / unit), next);
    }
  };
  const auto relax = [&](EntityIndex next, DurationNs through) {
    if (through >= label_[next]) return;  // closed, or no better
    label_[next] = through;
    queue(next, through);
  };
  if (!queued_root_) {
    queued_root_ = true;
    if (breadth_first) fifo_.reserve(graph.vertex_count());  // each vertex is queued once
    queue(root_, 0);
  }
  const Traversal::Adjacency& adjacency = traversal.adjacency(graph);
  while (breadth_first ? fifo_head_ < fifo_.size() : !open_.empty()) {
    const EntityIndex top = breadth_first ? fifo_[fifo_head_++] : open_.pop().value;
    const DurationNs distance = label_[top];
    if (distance < 0) continue;  // stale: popped before
    label_[top] = ~distance;
    if constexpr (kDirection == Direction::to_root) {
      // Backwards: the arcs into top lead from the vertices that can reach it.
      for (const Traversal::Hop& hop : adjacency.into_of(top)) relax(hop.from, distance + hop.travel);
    } else {  // a root the vehicle may not use leads nowhere (it has no moves)
      for (const Traversal::Move& move : adjacency.out_of(top)) relax(move.to, distance + move.travel);
    }
    if (top == vertex) return distance;
  }
  return kUnreachable;  // every vertex connected with the root is closed, and `vertex` is not
}

template class DistanceTable<Direction::to_root>;
template class DistanceTable<Direction::from_root>;

HeuristicTable& HeuristicCache::table(const RoutingGraph& graph, std::uint64_t class_id,
                                      EntityIndex goal) {
  for (Entry& entry : entries_) {
    if (entry.class_id == class_id && entry.table->root() == goal) {
      entry.last_request = request_;
      return *entry.table;
    }
  }
  Entry* slot = nullptr;
  if (entries_.size() >= capacity_) {
    // Replace the least recently used table that this request does not hold.
    for (Entry& entry : entries_) {
      if (entry.last_request != request_ &&
          (slot == nullptr || entry.last_request < slot->last_request)) {
        slot = &entry;
      }
    }
  }
  if (slot == nullptr) {
    entries_.push_back(Entry{std::make_unique<HeuristicTable>(), 0, 0});
    slot = &entries_.back();
  }
  slot->class_id = class_id;
  slot->last_request = request_;
  slot->table->reset(graph, goal);
  return *slot->table;
}

}  // namespace drover::carp
