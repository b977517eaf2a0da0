#include "heuristic.hpp"

#include <algorithm>

namespace drover::carp {

using topology::EntityIndex;

void HeuristicTable::reset(const RoutingGraph& graph, EntityIndex goal) {
  goal_ = goal;
  target_ = goal;
  distance_.assign(graph.vertex_count(), kUnreachable);
  closed_.assign(graph.vertex_count(), 0);
  open_.clear();
  distance_[goal] = 0;
  open_.push(Entry{0, 0, goal});
}

void HeuristicTable::aim(const RoutingGraph& graph, const Traversal& traversal,
                         EntityIndex target) {
  if (target == target_) return;
  target_ = target;
  open_.rebuild(
      [this](const Entry& e) { return !closed_[e.vertex] && e.distance == distance_[e.vertex]; },
      [&](Entry& e) { e.key = e.distance + traversal.lower_bound(graph, e.vertex, target); });
}

DurationNs HeuristicTable::resume(const RoutingGraph& graph, const Traversal& traversal,
                                  EntityIndex vertex) {
  while (!open_.empty()) {
    const Entry top = open_.pop();
    if (closed_[top.vertex] || top.distance != distance_[top.vertex]) continue;  // stale
    closed_[top.vertex] = 1;
    // Backwards: the arcs into top.vertex lead from the vertices that can reach it.
    for (const ArcIndex a : graph.arcs_into(top.vertex)) {
      const EntityIndex from = graph.arc(a).from;
      if (!traversal.usable_arc(a) || !traversal.usable_vertex(from) || closed_[from]) continue;
      const DurationNs through = top.distance + traversal.travel(a);
      if (through < distance_[from]) {
        distance_[from] = through;
        open_.push(Entry{through + traversal.lower_bound(graph, from, target_), through, from});
      }
    }
    if (top.vertex == vertex) return top.distance;
  }
  return kUnreachable;  // everything that reaches the goal is closed, and `vertex` is not
}

HeuristicTable& HeuristicCache::table(const RoutingGraph& graph, std::uint64_t class_id,
                                      EntityIndex goal) {
  for (Entry& entry : entries_) {
    if (entry.class_id == class_id && entry.table->goal() == goal) {
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
