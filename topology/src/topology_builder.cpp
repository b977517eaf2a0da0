#include "drover/topology/topology_builder.hpp"

#include <cmath>
#include <string_view>
#include <unordered_map>
#include <utility>

#include "drover/common/identifier.hpp"
#include "drover/topology/conflicts.hpp"
#include "drover/topology/footprints.hpp"

namespace drover::topology {

namespace bg = boost::geometry;

namespace {

/// "vertices[3]" + "id" -> "vertices[3].id"; a spec without a source location is named
/// by its position in the builder.
std::string field_of(const std::string& where, std::string_view field) {
  std::string place = where;
  if (!place.empty() && !field.empty()) place += '.';
  place += field;
  return place;
}

std::string where_or(const std::string& where, std::string_view list, std::size_t index) {
  if (!where.empty()) return where;
  return std::string(list) + "[" + std::to_string(index) + "]";
}

bool positive_finite(double value) { return std::isfinite(value) && value > 0; }

std::string in_quotes(std::string_view text) { return "'" + std::string(text) + "'"; }

class Validator {
 public:
  void report(std::string where, std::string what) {
    diagnostics_.push_back(Diagnostic{std::move(where), std::move(what)});
  }
  Diagnostics& diagnostics() { return diagnostics_; }

  void check_options(const FootprintOptions& options) {
    const auto size = [&](double value, std::string_view field) {
      if (!(value >= kMinFootprintOption && value <= kMaxFootprintOption)) {  // NaN too
        report(field_of("footprint_options", field),
               "must be a number from 0.01 to 10000 (metres)");
      }
    };
    size(options.vertex_radius, "vertex_radius");
    size(options.edge_half_width, "edge_half_width");
    if (options.disc_points < 3 || options.disc_points > kMaxDiscPoints) {
      report("footprint_options.disc_points",
             "must be between 3 and " + std::to_string(kMaxDiscPoints));
    }
  }

  void check_coordinate(double value, const std::string& where) {
    if (!std::isfinite(value)) {
      report(where, "must be finite");
    } else if (std::abs(value) > kMaxCoordinate) {
      report(where, "must lie within 1000000 m of the origin");
    }
  }

  /// Registers an id; reports one that breaks the identifier rule or is already used.
  void check_id(const std::string& id, const std::string& where) {
    if (auto problem = identifier_problem(id)) {
      report(field_of(where, "id"), *problem);
      return;
    }
    const auto [existing, inserted] = first_use_.emplace(id, where);
    if (!inserted) {
      report(field_of(where, "id"),
             "duplicate id " + in_quotes(id) + " (first used by " + existing->second + ")");
    }
  }

  void check_partition(const std::string& partition, const std::string& where) {
    if (partition.empty()) report(field_of(where, "partition"), "must not be empty");
  }

  void check_restrictions(const Restrictions& restrictions, const std::string& where) {
    const std::string base = field_of(where, "restrictions");
    const auto limit = [&](const std::optional<double>& value, std::string_view field,
                           bool zero_allowed) {
      if (!value) return;
      const bool ok = std::isfinite(*value) && (zero_allowed ? *value >= 0 : *value > 0);
      if (!ok) {
        report(field_of(base, field), zero_allowed ? "must be a non-negative finite number"
                                                   : "must be a positive finite number");
      }
    };
    // A zero speed limit would make the entity impassable with an infinite travel time;
    // a lock is the way to close an entity.
    limit(restrictions.max_speed, "max_speed", false);
    limit(restrictions.max_payload, "max_payload", true);
    limit(restrictions.max_vehicle_length, "max_vehicle_length", true);
    limit(restrictions.max_vehicle_width, "max_vehicle_width", true);
    const auto names = [&](const std::vector<std::string>& types, std::string_view field) {
      for (std::size_t i = 0; i < types.size(); ++i) {
        if (types[i].empty()) {
          report(field_of(base, field) + "[" + std::to_string(i) + "]",
                 "vehicle type must not be empty");
        }
      }
    };
    names(restrictions.allowed_vehicle_types, "allowed_vehicle_types");
    names(restrictions.forbidden_vehicle_types, "forbidden_vehicle_types");
  }

  void check_footprint(std::optional<Polygon>& footprint, const std::string& where) {
    if (!footprint) return;
    if (auto reason = normalize_footprint(*footprint)) {
      report(field_of(where, "footprint"), std::move(*reason));
    }
  }

 private:
  Diagnostics diagnostics_;
  std::unordered_map<std::string, std::string> first_use_;  // id -> where it was first used
};

}  // namespace

std::string diagnostic_text(const std::string& file, const Diagnostic& problem) {
  return file + (problem.where.empty() ? "" : ":" + problem.where) + ": " + problem.what;
}

TopologyBuilder::TopologyBuilder(std::string name, FootprintOptions options)
    : name_(std::move(name)), options_(options) {}

void TopologyBuilder::add_vertex(VertexSpec vertex) { vertices_.push_back(std::move(vertex)); }

void TopologyBuilder::add_edge(EdgeSpec edge) { edges_.push_back(std::move(edge)); }

Result<Topology, Diagnostics> TopologyBuilder::build() && {
  Validator check;
  check.check_options(options_);

  std::unordered_map<std::string, EntityIndex> vertex_by_id;
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    auto& spec = vertices_[i];
    spec.where = where_or(spec.where, "vertices", i);
    check.check_id(spec.id, spec.where);
    vertex_by_id.emplace(spec.id, static_cast<EntityIndex>(i));
    check.check_coordinate(spec.x, field_of(spec.where, "x"));
    check.check_coordinate(spec.y, field_of(spec.where, "y"));
    if (spec.orientation && !std::isfinite(*spec.orientation)) {
      check.report(field_of(spec.where, "orientation"), "must be finite");
    }
    check.check_footprint(spec.footprint, spec.where);
    check.check_restrictions(spec.restrictions, spec.where);
    check.check_partition(spec.partition, spec.where);
  }

  for (std::size_t i = 0; i < edges_.size(); ++i) {
    auto& spec = edges_[i];
    spec.where = where_or(spec.where, "edges", i);
    check.check_id(spec.id, spec.where);
    for (const auto& [end, field] : {std::pair{&spec.from, "from"}, std::pair{&spec.to, "to"}}) {
      if (end->empty()) {
        check.report(field_of(spec.where, field), "must name a vertex");
      } else if (!vertex_by_id.contains(*end)) {
        check.report(field_of(spec.where, field), "unknown vertex " + in_quotes(*end));
      }
    }
    if (!spec.from.empty() && spec.from == spec.to) {
      check.report(field_of(spec.where, "to"), "must differ from 'from' (" + in_quotes(spec.to) +
                                                   " is both ends)");
    }
    if (spec.length && !positive_finite(*spec.length)) {
      check.report(field_of(spec.where, "length"), "must be a positive finite number");
    } else if (spec.length && *spec.length > kMaxEdgeLength) {
      check.report(field_of(spec.where, "length"), "must be at most 10000000 (metres)");
    }
    if (!positive_finite(spec.max_speed)) {
      check.report(field_of(spec.where, "max_speed"), "must be a positive finite number");
    }
    check.check_footprint(spec.footprint, spec.where);
    check.check_restrictions(spec.restrictions, spec.where);
    check.check_partition(spec.partition, spec.where);
  }
  if (!check.diagnostics().empty()) return unexpected(std::move(check.diagnostics()));

  // The input is consistent; derive what it left out.
  Topology topology;
  topology.name_ = std::move(name_);
  topology.footprint_options_ = options_;
  topology.vertices_.reserve(vertices_.size());
  for (auto& spec : vertices_) {
    Vertex vertex;
    vertex.id = std::move(spec.id);
    vertex.position = Point{spec.x, spec.y};
    vertex.orientation = spec.orientation;
    vertex.kind = spec.kind;
    vertex.footprint_generated = !spec.footprint;
    vertex.footprint = spec.footprint ? std::move(*spec.footprint)
                                      : vertex_footprint(vertex.position, options_);
    vertex.restrictions = std::move(spec.restrictions);
    vertex.properties = std::move(spec.properties);
    vertex.partition = std::move(spec.partition);
    topology.vertices_.push_back(std::move(vertex));
  }

  topology.edges_.reserve(edges_.size());
  for (auto& spec : edges_) {
    Edge edge;
    edge.id = std::move(spec.id);
    edge.from = vertex_by_id.at(spec.from);
    edge.to = vertex_by_id.at(spec.to);
    edge.bidirectional = spec.bidirectional;
    const Vertex& from = topology.vertices_[edge.from];
    const Vertex& to = topology.vertices_[edge.to];
    const double distance = bg::distance(from.position, to.position);
    if (spec.length) {
      edge.length = *spec.length;
    } else if (positive_finite(distance)) {
      edge.length = distance;
    } else {
      check.report(field_of(spec.where, "length"),
                   "not given, and the end vertices are at the same position");
    }
    edge.max_speed = spec.max_speed;
    edge.footprint_generated = !spec.footprint;
    if (spec.footprint) {
      edge.footprint = std::move(*spec.footprint);
    } else if (!positive_finite(distance)) {
      check.report(field_of(spec.where, "footprint"),
                   "cannot be generated: the end vertices are at the same position");
    } else if (auto generated = edge_footprint(from.position, to.position, from.footprint,
                                               to.footprint, options_)) {
      edge.footprint = std::move(*generated);
    } else {
      check.report(field_of(spec.where, "footprint"),
                   "cannot be generated: the end vertices' footprints cover the whole edge "
                   "(vertices too close for the footprint options); give one explicitly");
    }
    edge.restrictions = std::move(spec.restrictions);
    edge.properties = std::move(spec.properties);
    edge.partition = std::move(spec.partition);
    topology.edges_.push_back(std::move(edge));
  }
  if (!check.diagnostics().empty()) return unexpected(std::move(check.diagnostics()));

  const auto vertex_count = static_cast<EntityIndex>(topology.vertices_.size());
  topology.moves_.resize(topology.vertices_.size());
  std::vector<const Polygon*> footprints;
  footprints.reserve(topology.entity_count());
  for (EntityIndex v = 0; v < vertex_count; ++v) {
    topology.index_by_id_.emplace(topology.vertices_[v].id, v);
    footprints.push_back(&topology.vertices_[v].footprint);
  }
  for (std::size_t i = 0; i < topology.edges_.size(); ++i) {
    const Edge& edge = topology.edges_[i];
    const auto index = static_cast<EntityIndex>(vertex_count + i);
    topology.index_by_id_.emplace(edge.id, index);
    footprints.push_back(&edge.footprint);
    topology.moves_[edge.from].push_back(Move{index, edge.to});
    if (edge.bidirectional) topology.moves_[edge.to].push_back(Move{index, edge.from});
  }

  topology.conflicts_ = compute_conflict_sets(footprints);
  std::size_t memberships = 0;
  for (const auto& set : topology.conflicts_) memberships += set.size();
  topology.conflict_pairs_ = memberships / 2;
  return topology;
}

}  // namespace drover::topology
