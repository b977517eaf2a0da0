#pragma once
// The driving topology: vertices and edges ("entities"), with footprints, restrictions
// and the conflict sets derived from the footprints. Immutable once built; build one with
// TopologyBuilder (topology_builder.hpp) or a loader (json_format.hpp, movingai.hpp).

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "drover/topology/geometry.hpp"

namespace drover::topology {

/// Dense index of an entity: vertices take [0, vertex_count), edges follow them.
using EntityIndex = std::uint32_t;
inline constexpr EntityIndex kNoEntity = std::numeric_limits<EntityIndex>::max();

enum class EntityKind { vertex, edge };
enum class VertexKind { waypoint, station, parking, charger };

/// Stable lower-case names used by file formats and tools.
const char* to_string(VertexKind kind) noexcept;
std::optional<VertexKind> vertex_kind_from_string(std::string_view name) noexcept;

/// Free key/value properties, kept as given by the file.
using Properties = std::map<std::string, std::string>;

/// What a vehicle must satisfy to use an entity. Empty optionals / lists mean "no limit".
struct Restrictions {
  std::optional<double> max_speed;    ///< m/s
  std::optional<double> max_payload;  ///< kg
  std::vector<std::string> allowed_vehicle_types;    ///< empty: every type allowed
  std::vector<std::string> forbidden_vehicle_types;  ///< checked after allowed types
  std::optional<double> max_vehicle_length;  ///< m
  std::optional<double> max_vehicle_width;   ///< m

  friend bool operator==(const Restrictions&, const Restrictions&) = default;
};

struct Vertex {
  std::string id;
  Point position;                      ///< metres
  std::optional<double> orientation;   ///< radians, when the vehicle must face a direction
  VertexKind kind = VertexKind::waypoint;
  Polygon footprint;                   ///< always set once built (generated when not given)
  bool footprint_generated = false;    ///< true when the file gave none
  Restrictions restrictions;
  Properties properties;
  std::string partition;               ///< the topology agent partition that owns it
};

struct Edge {
  std::string id;
  EntityIndex from = kNoEntity;        ///< vertex index
  EntityIndex to = kNoEntity;          ///< vertex index
  bool bidirectional = false;          ///< false: only from -> to may be driven
  double length = 0;                   ///< metres, > 0
  double max_speed = 0;                ///< m/s, > 0
  Polygon footprint;                   ///< always set once built (generated when not given)
  bool footprint_generated = false;
  Restrictions restrictions;
  Properties properties;
  std::string partition;
};

/// One way to leave a vertex: through `edge` to `to` (a bidirectional edge appears in the
/// adjacency of both its end vertices).
struct Move {
  EntityIndex edge;
  EntityIndex to;
};

/// How footprints are generated where a file gives none.
struct FootprintOptions {
  double vertex_radius = 0.5;     ///< m; half the side of a vertex square, or the disc radius
  bool vertex_disc = false;       ///< false: square footprints, true: discs
  int disc_points = 16;           ///< corners of a disc approximation
  double edge_half_width = 0.5;   ///< m; half the width of a buffered edge segment
};

/// An immutable, validated topology. Every entity has a footprint and a conflict set.
class Topology {
 public:
  const std::string& name() const noexcept { return name_; }

  std::size_t vertex_count() const noexcept { return vertices_.size(); }
  std::size_t edge_count() const noexcept { return edges_.size(); }
  std::size_t entity_count() const noexcept { return vertices_.size() + edges_.size(); }

  EntityKind kind(EntityIndex entity) const noexcept {
    return entity < vertices_.size() ? EntityKind::vertex : EntityKind::edge;
  }
  bool is_vertex(EntityIndex entity) const noexcept { return entity < vertices_.size(); }
  bool is_edge(EntityIndex entity) const noexcept {
    return entity >= vertices_.size() && entity < entity_count();
  }

  /// \pre is_vertex(entity)
  const Vertex& vertex(EntityIndex entity) const { return vertices_[entity]; }
  /// \pre is_edge(entity)
  const Edge& edge(EntityIndex entity) const { return edges_[entity - vertices_.size()]; }
  const std::vector<Vertex>& vertices() const noexcept { return vertices_; }
  const std::vector<Edge>& edges() const noexcept { return edges_; }

  /// The entity with this id, if any (vertex and edge ids share one namespace).
  std::optional<EntityIndex> find(std::string_view id) const;
  /// \pre entity < entity_count()
  const std::string& id(EntityIndex entity) const;
  const Polygon& footprint(EntityIndex entity) const;
  const Restrictions& restrictions(EntityIndex entity) const;
  const std::string& partition(EntityIndex entity) const;

  /// C(e): the other entities whose footprints overlap e's interior, sorted ascending.
  /// Symmetric: f in C(e) iff e in C(f). Never contains e itself.
  std::span<const EntityIndex> conflicts(EntityIndex entity) const;
  /// Number of unordered pairs {e, f} with f in C(e).
  std::size_t conflict_pair_count() const noexcept { return conflict_pairs_; }
  /// The conflict sets of all entities, indexed by entity (for the timelines).
  const std::vector<std::vector<EntityIndex>>& conflict_sets() const noexcept {
    return conflicts_;
  }

  /// The moves out of a vertex, in edge order. \pre is_vertex(vertex)
  std::span<const Move> moves_from(EntityIndex vertex) const;

  /// The partitions named by the entities, sorted, without duplicates.
  std::vector<std::string> partitions() const;

  /// The options footprints were generated with.
  const FootprintOptions& footprint_options() const noexcept { return footprint_options_; }

 private:
  friend class TopologyBuilder;

  std::string name_;
  std::vector<Vertex> vertices_;
  std::vector<Edge> edges_;
  std::unordered_map<std::string, EntityIndex> index_by_id_;
  std::vector<std::vector<EntityIndex>> conflicts_;
  std::size_t conflict_pairs_ = 0;
  std::vector<std::vector<Move>> moves_;  // per vertex
  FootprintOptions footprint_options_;
};

}  // namespace drover::topology
