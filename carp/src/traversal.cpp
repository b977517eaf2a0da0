#include "traversal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <fmt/format.h>

namespace drover::carp {

using topology::EntityIndex;

Traversal::Traversal(const RoutingGraph& graph, const VehicleProfile& vehicle)
    : vehicle_(vehicle) {
  const topology::Topology& topology = graph.topology();
  usable_vertex_.resize(graph.vertex_count());
  for (EntityIndex v = 0; v < graph.vertex_count(); ++v) {
    usable_vertex_[v] = !restriction_violation(topology.vertex(v).restrictions, vehicle);
  }
  const std::size_t arcs = graph.arc_count();
  travel_.resize(arcs);
  clearance_.resize(arcs);
  usable_arc_.resize(arcs);
  double ns_per_metre = std::numeric_limits<double>::infinity();
  DurationNs shortest = kForever;
  DurationNs longest = 0;
  const auto most_ns = static_cast<double>(max_arc_time(graph.vertex_count()));
  for (ArcIndex a = 0; a < arcs; ++a) {
    const Arc& arc = graph.arc(a);
    const double speed = std::min(vehicle.max_speed, arc.speed_limit);
    const double travel_ns = arc.length / speed * 1e9;
    const double clearance_ns = vehicle.length / speed * 1e9;
    usable_arc_[a] = usable_vertex_[arc.to] &&
                     !restriction_violation(topology.edge(arc.edge).restrictions, vehicle);
    // Only an arc the vehicle may drive can make it too slow: the others' times are never
    // added up.
    const double longer_ns = std::max(travel_ns, clearance_ns);
    if (usable_arc_[a] && usable_vertex_[arc.from] && longer_ns > most_ns &&
        (!too_slow_arc_ || longer_ns > too_slow_arc_->seconds * 1e9)) {
      too_slow_arc_ = SlowArc{a, longer_ns / 1e9};
    }
    // Clipped before the conversion, which is undefined beyond the integer's range.
    travel_[a] = std::max<DurationNs>(1, std::llround(std::min(travel_ns, most_ns)));
    clearance_[a] =
        std::max<DurationNs>(1, static_cast<DurationNs>(std::ceil(std::min(clearance_ns, most_ns))));
    if (usable_arc_[a]) {
      shortest = std::min(shortest, travel_[a]);
      longest = std::max(longest, travel_[a]);
    }
    const double straight = graph.straight_distance(arc.from, arc.to);
    if (straight > 0) {
      ns_per_metre = std::min(ns_per_metre, static_cast<double>(travel_[a]) / straight);
    }
  }
  // Shrunk a little so that floating-point error in the triangle inequality can never make
  // the bound inconsistent by a nanosecond.
  ns_per_metre_ = std::isfinite(ns_per_metre) ? ns_per_metre * (1 - 1e-9) : 0;
  min_travel_ = shortest == kForever ? 1 : shortest;
  uniform_ = shortest == kForever || shortest == longest;
}

std::optional<std::string> Traversal::too_slow(const RoutingGraph& graph,
                                               const std::string& vehicle_id) const {
  if (!too_slow_arc_) return std::nullopt;
  const topology::Topology& topology = graph.topology();
  return fmt::format(
      "vehicle '{}' is too slow (or too long) for topology '{}': it would take {:.6g} s to "
      "drive or clear edge '{}', more than the {:.6g} s allowed per arc on {} vertices (so "
      "that no route's times overflow)",
      vehicle_id, topology.name(), too_slow_arc_->seconds,
      topology.id(graph.arc(too_slow_arc_->arc).edge),
      ns_to_seconds(max_arc_time(graph.vertex_count())), graph.vertex_count());
}

void Traversal::find_components(const RoutingGraph& graph) const {
  const std::size_t n = graph.vertex_count();
  constexpr std::uint32_t kUnset = 0xffffffffu;
  // 1. Vertices in order of finishing a depth-first search along the usable arcs.
  std::vector<EntityIndex> finished;
  finished.reserve(n);
  std::vector<std::uint8_t> seen(n, 0);
  std::vector<std::pair<EntityIndex, ArcIndex>> stack;  // vertex, next arc to try
  for (EntityIndex root = 0; root < n; ++root) {
    if (seen[root]) continue;
    seen[root] = 1;
    stack.emplace_back(root, graph.arcs_begin(root));
    while (!stack.empty()) {
      auto& [v, a] = stack.back();
      if (a == graph.arcs_end(v)) {
        finished.push_back(v);
        stack.pop_back();
        continue;
      }
      const ArcIndex arc = a++;
      const EntityIndex to = graph.arc(arc).to;
      if (usable_arc_[arc] && !seen[to]) {
        seen[to] = 1;
        stack.emplace_back(to, graph.arcs_begin(to));
      }
    }
  }
  // 2. In reverse finishing order, what reaches each new root backwards is its component.
  component_.assign(n, kUnset);
  std::vector<EntityIndex> pending;
  std::uint32_t next = 0;
  for (auto it = finished.rbegin(); it != finished.rend(); ++it) {
    if (component_[*it] != kUnset) continue;
    component_[*it] = next;
    pending.push_back(*it);
    while (!pending.empty()) {
      const EntityIndex v = pending.back();
      pending.pop_back();
      for (const ArcIndex arc : graph.arcs_into(v)) {
        const EntityIndex from = graph.arc(arc).from;
        if (usable_arc_[arc] && component_[from] == kUnset) {
          component_[from] = next;
          pending.push_back(from);
        }
      }
    }
    ++next;
  }
}

void Traversal::build_adjacency(const RoutingGraph& graph) const {
  const std::size_t n = graph.vertex_count();
  Adjacency& adjacency = adjacency_;
  adjacency.into_first.assign(n + 1, 0);
  adjacency.out_first.assign(n + 1, 0);
  const std::size_t arcs = graph.arc_count();
  adjacency.into.reserve(arcs);
  adjacency.into_from.reserve(arcs);
  adjacency.out.reserve(arcs);
  adjacency.out_to.reserve(arcs);
  std::map<Timing, std::uint32_t> timing_ids;
  // Most arcs take the time of the arc before (a grid's all do): that one is asked first.
  Timing last_timing{-1, -1};
  std::uint32_t last_id = 0;
  const auto timing_of = [&](ArcIndex a) {
    const Timing timing{travel(a), clearance(a)};
    if (timing == last_timing) return last_id;
    const auto id = timing_ids.try_emplace(timing, adjacency.timings.size()).first->second;
    if (id == adjacency.timings.size()) adjacency.timings.push_back(timing);
    last_timing = timing;
    last_id = id;
    return id;
  };
  for (EntityIndex v = 0; v < n; ++v) {
    adjacency.into_first[v] = static_cast<std::uint32_t>(adjacency.into.size());
    for (const ArcIndex a : graph.arcs_into(v)) {
      const EntityIndex from = graph.arc(a).from;
      if (usable_arc(a) && usable_vertex(from)) {
        adjacency.into.push_back(Hop{timing_of(a), from, graph.arc(a).edge});
        adjacency.into_from.push_back(from);
      }
    }
    adjacency.out_first[v] = static_cast<std::uint32_t>(adjacency.out.size());
    if (!usable_vertex(v)) continue;
    for (ArcIndex a = graph.arcs_begin(v); a != graph.arcs_end(v); ++a) {
      if (!usable_arc(a)) continue;
      const Arc& arc = graph.arc(a);
      adjacency.out.push_back(Move{timing_of(a), a, arc.edge, arc.to});
      adjacency.out_to.push_back(arc.to);
    }
  }
  adjacency.into_first[n] = static_cast<std::uint32_t>(adjacency.into.size());
  adjacency.out_first[n] = static_cast<std::uint32_t>(adjacency.out.size());
  std::uint32_t degree = 0;
  for (EntityIndex v = 0; v < n; ++v) {
    degree = std::max({degree, adjacency.into_first[v + 1] - adjacency.into_first[v],
                       adjacency.out_first[v + 1] - adjacency.out_first[v]});
  }
  if (degree == 0 || degree > Adjacency::kMaxPaddedDegree) return;
  adjacency.padded_degree = degree;
  const auto pad = [&](const std::vector<std::uint32_t>& first,
                       const std::vector<EntityIndex>& vertices, std::vector<EntityIndex>& padded) {
    padded.assign(std::size_t{n} * degree, static_cast<EntityIndex>(n));
    for (EntityIndex v = 0; v < n; ++v) {
      std::copy(vertices.begin() + first[v], vertices.begin() + first[v + 1],
                padded.begin() + std::size_t{v} * degree);
    }
  };
  pad(adjacency.into_first, adjacency.into_from, adjacency.padded_into_from);
  pad(adjacency.out_first, adjacency.out_to, adjacency.padded_out_to);
}

bool Traversal::same_class(const VehicleProfile& a, const VehicleProfile& b) {
  return a.max_speed == b.max_speed && a.length == b.length && a.width == b.width &&
         a.payload == b.payload && a.type == b.type;
}

TraversalCache::Found TraversalCache::get(const RoutingGraph& graph,
                                          const VehicleProfile& vehicle) {
  ++clock_;
  for (Entry& entry : entries_) {
    if (Traversal::same_class(entry.traversal->vehicle(), vehicle)) {
      entry.last_used = clock_;
      return {entry.traversal.get(), entry.class_id};
    }
  }
  Entry fresh{std::make_unique<Traversal>(graph, vehicle), next_class_id_++, clock_};
  const Found found{fresh.traversal.get(), fresh.class_id};
  if (entries_.size() < capacity_) {
    entries_.push_back(std::move(fresh));
  } else {
    *std::min_element(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
      return a.last_used < b.last_used;
    }) = std::move(fresh);
  }
  return found;
}

}  // namespace drover::carp
