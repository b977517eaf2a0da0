#include "drover/topology/model.hpp"

#include <algorithm>
#include <array>
#include <set>
#include <utility>

namespace drover::topology {

namespace {
constexpr std::array<std::pair<VertexKind, const char*>, 4> kVertexKindNames{{
    {VertexKind::waypoint, "waypoint"},
    {VertexKind::station, "station"},
    {VertexKind::parking, "parking"},
    {VertexKind::charger, "charger"},
}};
}  // namespace

const char* to_string(VertexKind kind) noexcept {
  for (const auto& [value, name] : kVertexKindNames) {
    if (value == kind) return name;
  }
  return "waypoint";
}

std::optional<VertexKind> vertex_kind_from_string(std::string_view name) noexcept {
  for (const auto& [value, text] : kVertexKindNames) {
    if (name == text) return value;
  }
  return std::nullopt;
}

std::optional<EntityIndex> Topology::find(std::string_view id) const {
  const auto found = index_by_id_.find(std::string(id));
  if (found == index_by_id_.end()) return std::nullopt;
  return found->second;
}

const std::string& Topology::id(EntityIndex entity) const {
  return is_vertex(entity) ? vertex(entity).id : edge(entity).id;
}

const Polygon& Topology::footprint(EntityIndex entity) const {
  return is_vertex(entity) ? vertex(entity).footprint : edge(entity).footprint;
}

const Restrictions& Topology::restrictions(EntityIndex entity) const {
  return is_vertex(entity) ? vertex(entity).restrictions : edge(entity).restrictions;
}

const std::string& Topology::partition(EntityIndex entity) const {
  return is_vertex(entity) ? vertex(entity).partition : edge(entity).partition;
}

std::span<const EntityIndex> Topology::conflicts(EntityIndex entity) const {
  return conflicts_[entity];
}

std::span<const Move> Topology::moves_from(EntityIndex vertex_index) const {
  return moves_[vertex_index];
}

std::vector<std::string> Topology::partitions() const {
  std::set<std::string> names;
  for (const auto& v : vertices_) names.insert(v.partition);
  for (const auto& e : edges_) names.insert(e.partition);
  return {names.begin(), names.end()};
}

}  // namespace drover::topology
