#include "drover/carp/free_path.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "min_heap.hpp"
#include "traversal.hpp"

namespace drover::carp {

using topology::EntityIndex;

struct FreePathSearch::Impl {
  struct Entry {
    DurationNs key;
    DurationNs time;
    EntityIndex vertex;
    bool operator>(const Entry& o) const { return key != o.key ? key > o.key : time < o.time; }
  };

  std::shared_ptr<const RoutingGraph> graph;
  TraversalCache traversals{4};
  std::uint32_t generation = 0;
  std::vector<std::uint32_t> stamp;
  std::vector<DurationNs> time;
  std::vector<ArcIndex> via;
  std::vector<std::uint8_t> closed;
  MinHeap<Entry> open;

  void begin() {
    const std::size_t n = graph->vertex_count();
    if (stamp.size() != n || ++generation == 0) {
      stamp.assign(n, 0);
      time.resize(n);
      via.resize(n);
      closed.resize(n);
      generation = 1;
    }
    open.clear();
  }
  void touch(EntityIndex v) {
    if (stamp[v] == generation) return;
    stamp[v] = generation;
    time[v] = kUnreachable;
    closed[v] = 0;
  }
};

FreePathSearch::FreePathSearch(std::shared_ptr<const RoutingGraph> graph)
    : impl_(std::make_unique<Impl>()) {
  impl_->graph = std::move(graph);
}
FreePathSearch::~FreePathSearch() = default;

Result<FreePath> FreePathSearch::find(const VehicleProfile& vehicle, EntityIndex start,
                                      EntityIndex goal) {
  Impl& m = *impl_;
  const RoutingGraph& graph = *m.graph;
  if (auto valid = validate(vehicle); !valid) return unexpected(valid.error());
  for (const EntityIndex v : {start, goal}) {
    if (v >= graph.vertex_count()) {
      return fail(ErrorCode::not_found, fmt::format("entity {} is not a vertex", v));
    }
  }
  const Traversal& traversal = *m.traversals.get(graph, vehicle).traversal;
  if (auto slow = traversal.too_slow(graph, vehicle.id)) {
    return fail(ErrorCode::invalid_argument, std::move(*slow));
  }
  m.begin();
  if (traversal.usable_vertex(start)) {
    m.touch(start);
    m.time[start] = 0;
    m.open.push(Impl::Entry{traversal.lower_bound(graph, start, goal), 0, start});
  }
  while (!m.open.empty()) {
    const Impl::Entry top = m.open.pop();
    if (m.closed[top.vertex] || top.time != m.time[top.vertex]) continue;
    m.closed[top.vertex] = 1;
    if (top.vertex == goal) break;
    for (ArcIndex a = graph.arcs_begin(top.vertex); a != graph.arcs_end(top.vertex); ++a) {
      if (!traversal.usable_arc(a)) continue;
      const EntityIndex next = graph.arc(a).to;
      m.touch(next);
      const DurationNs through = top.time + traversal.travel(a);
      if (!m.closed[next] && through < m.time[next]) {
        m.time[next] = through;
        m.via[next] = a;
        m.open.push(Impl::Entry{through + traversal.lower_bound(graph, next, goal), through, next});
      }
    }
  }
  m.touch(goal);
  if (!m.closed[goal]) {
    return fail(ErrorCode::unavailable,
                fmt::format("vehicle '{}' cannot reach '{}' from '{}'", vehicle.id,
                            graph.topology().id(goal), graph.topology().id(start)));
  }
  FreePath path;
  path.travel_time = m.time[goal];
  for (EntityIndex v = goal; v != start; v = graph.arc(m.via[v]).from) {
    path.vertices.push_back(v);
    path.distance += graph.arc(m.via[v]).length;
  }
  path.vertices.push_back(start);
  std::reverse(path.vertices.begin(), path.vertices.end());
  return path;
}

}  // namespace drover::carp
