#include "drover/topology/json_format.hpp"

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <utility>

#include <nlohmann/json.hpp>

#include "drover/common/json_document.hpp"
#include "drover/common/text_file.hpp"
#include "drover/topology/footprints.hpp"

namespace drover::topology {

namespace {

// Ordered, so that diagnostics follow the file and written files keep a readable order.
using Json = nlohmann::ordered_json;

/// Turns a parsed document into builder specs, collecting every structural problem (wrong
/// type, missing or unknown field) with its JSON path.
class SpecReader {
 public:
  Diagnostics& diagnostics() { return diagnostics_; }

  std::optional<TopologyBuilder> read_document(const Json& document) {
    if (!expect_object(document, "")) return std::nullopt;
    only_fields(document, "",
                {"name", "footprint_options", "vertices", "edges"});
    const auto name = string_field(document, "name", "", true);
    FootprintOptions options;
    if (const Json* given = field(document, "footprint_options", "", false)) {
      read_footprint_options(*given, options);
    }
    TopologyBuilder builder(name.value_or(""), options);
    if (const Json* vertices = array_field(document, "vertices", "")) {
      for (std::size_t i = 0; i < vertices->size(); ++i) {
        if (auto spec = read_vertex((*vertices)[i], json_element_path("vertices", i))) {
          builder.add_vertex(std::move(*spec));
        }
      }
    }
    if (const Json* edges = array_field(document, "edges", "")) {
      for (std::size_t i = 0; i < edges->size(); ++i) {
        if (auto spec = read_edge((*edges)[i], json_element_path("edges", i))) {
          builder.add_edge(std::move(*spec));
        }
      }
    }
    return builder;
  }

 private:
  void report(std::string where, std::string what) {
    diagnostics_.push_back(Diagnostic{std::move(where), std::move(what)});
  }

  void wrong_type(const Json& value, const std::string& where, std::string_view expected) {
    report(where, "expected " + std::string(expected) + ", got " + value.type_name());
  }

  bool expect_object(const Json& value, const std::string& where) {
    if (value.is_object()) return true;
    wrong_type(value, where.empty() ? "(document)" : where, "an object");
    return false;
  }

  /// Reports every member of `object` not in `allowed`: a misspelt field must not pass.
  void only_fields(const Json& object, const std::string& where,
                   std::initializer_list<std::string_view> allowed) {
    for (const auto& [key, value] : object.items()) {
      bool known = false;
      for (const auto name : allowed) known = known || key == name;
      if (known) continue;
      std::string expected;
      for (const auto name : allowed) {
        expected += expected.empty() ? "" : ", ";
        expected += name;
      }
      report(json_member_path(where, key), "unknown field (expected one of: " + expected + ")");
    }
  }

  const Json* field(const Json& object, std::string_view key, const std::string& where,
                    bool required) {
    const auto found = object.find(std::string(key));
    if (found == object.end()) {
      if (required) report(json_member_path(where, key), "required field is missing");
      return nullptr;
    }
    return &*found;
  }

  const Json* array_field(const Json& object, std::string_view key, const std::string& where) {
    const Json* value = field(object, key, where, true);
    if (value == nullptr) return nullptr;
    if (!value->is_array()) {
      wrong_type(*value, json_member_path(where, key), "an array");
      return nullptr;
    }
    return value;
  }

  std::optional<std::string> string_field(const Json& object, std::string_view key,
                                          const std::string& where, bool required) {
    const Json* value = field(object, key, where, required);
    if (value == nullptr) return std::nullopt;
    if (!value->is_string()) {
      wrong_type(*value, json_member_path(where, key), "a string");
      return std::nullopt;
    }
    return value->get<std::string>();
  }

  std::optional<double> number_field(const Json& object, std::string_view key,
                                     const std::string& where, bool required) {
    const Json* value = field(object, key, where, required);
    if (value == nullptr) return std::nullopt;
    if (!value->is_number()) {
      wrong_type(*value, json_member_path(where, key), "a number");
      return std::nullopt;
    }
    return value->get<double>();
  }

  std::optional<bool> bool_field(const Json& object, std::string_view key,
                                 const std::string& where) {
    const Json* value = field(object, key, where, false);
    if (value == nullptr) return std::nullopt;
    if (!value->is_boolean()) {
      wrong_type(*value, json_member_path(where, key), "a boolean");
      return std::nullopt;
    }
    return value->get<bool>();
  }

  void read_footprint_options(const Json& object, FootprintOptions& options) {
    const std::string where = "footprint_options";
    if (!expect_object(object, where)) return;
    only_fields(object, where, {"vertex_shape", "vertex_radius", "disc_points",
                                "edge_half_width"});
    if (const auto shape = string_field(object, "vertex_shape", where, false)) {
      if (*shape == "square" || *shape == "disc") {
        options.vertex_disc = *shape == "disc";
      } else {
        report(json_member_path(where, "vertex_shape"),
               "unknown shape '" + *shape + "' (expected square or disc)");
      }
    }
    if (const auto radius = number_field(object, "vertex_radius", where, false)) {
      options.vertex_radius = *radius;
    }
    if (const auto half_width = number_field(object, "edge_half_width", where, false)) {
      options.edge_half_width = *half_width;
    }
    if (const Json* points = field(object, "disc_points", where, false)) {
      // The builder checks the range; out-of-int values fall outside it as well.
      if (points->is_number_unsigned() || points->is_number_integer()) {
        const auto count = points->get<std::int64_t>();
        options.disc_points = count > kMaxDiscPoints ? kMaxDiscPoints + 1
                              : count < 0            ? -1
                                                     : static_cast<int>(count);
      } else {
        wrong_type(*points, json_member_path(where, "disc_points"), "an integer");
      }
    }
  }

  std::optional<Polygon> read_footprint(const Json& object, const std::string& where) {
    const Json* value = field(object, "footprint", where, false);
    if (value == nullptr) return std::nullopt;
    const std::string path = json_member_path(where, "footprint");
    if (!value->is_array()) {
      wrong_type(*value, path, "an array of [x, y] points");
      return std::nullopt;
    }
    Polygon polygon;
    bool complete = true;
    for (std::size_t i = 0; i < value->size(); ++i) {
      const Json& point = (*value)[i];
      if (!point.is_array() || point.size() != 2 || !point[0].is_number() ||
          !point[1].is_number()) {
        std::string got = point.type_name();
        if (point.is_array() && point.size() != 2) {
          got = "an array of " + std::to_string(point.size()) + " elements";
        } else if (point.is_array()) {
          got = std::string("[") + point[0].type_name() + ", " + point[1].type_name() + "]";
        }
        report(json_element_path(path, i), "expected a point [x, y] of two numbers, got " + got);
        complete = false;
        continue;
      }
      polygon.outer().emplace_back(point[0].get<double>(), point[1].get<double>());
    }
    if (!complete) return std::nullopt;
    return polygon;
  }

  std::vector<std::string> string_list(const Json& object, std::string_view key,
                                       const std::string& where) {
    std::vector<std::string> list;
    const Json* value = field(object, key, where, false);
    if (value == nullptr) return list;
    const std::string path = json_member_path(where, key);
    if (!value->is_array()) {
      wrong_type(*value, path, "an array of strings");
      return list;
    }
    for (std::size_t i = 0; i < value->size(); ++i) {
      if ((*value)[i].is_string()) {
        list.push_back((*value)[i].get<std::string>());
      } else {
        wrong_type((*value)[i], json_element_path(path, i), "a string");
      }
    }
    return list;
  }

  Restrictions read_restrictions(const Json& object, const std::string& owner) {
    Restrictions restrictions;
    const Json* value = field(object, "restrictions", owner, false);
    if (value == nullptr) return restrictions;
    const std::string where = json_member_path(owner, "restrictions");
    if (!expect_object(*value, where)) return restrictions;
    only_fields(*value, where,
                {"max_speed", "max_payload", "allowed_vehicle_types", "forbidden_vehicle_types",
                 "max_vehicle_length", "max_vehicle_width"});
    restrictions.max_speed = number_field(*value, "max_speed", where, false);
    restrictions.max_payload = number_field(*value, "max_payload", where, false);
    restrictions.allowed_vehicle_types = string_list(*value, "allowed_vehicle_types", where);
    restrictions.forbidden_vehicle_types = string_list(*value, "forbidden_vehicle_types", where);
    restrictions.max_vehicle_length = number_field(*value, "max_vehicle_length", where, false);
    restrictions.max_vehicle_width = number_field(*value, "max_vehicle_width", where, false);
    return restrictions;
  }

  Properties read_properties(const Json& object, const std::string& owner) {
    Properties properties;
    const Json* value = field(object, "properties", owner, false);
    if (value == nullptr) return properties;
    const std::string where = json_member_path(owner, "properties");
    if (!expect_object(*value, where)) return properties;
    for (const auto& [key, text] : value->items()) {
      if (text.is_string()) {
        properties.emplace(key, text.get<std::string>());
      } else {
        wrong_type(text, json_member_path(where, key), "a string");
      }
    }
    return properties;
  }

  std::optional<VertexSpec> read_vertex(const Json& object, const std::string& where) {
    if (!expect_object(object, where)) return std::nullopt;
    only_fields(object, where, {"id", "x", "y", "orientation", "kind", "footprint",
                                "restrictions", "properties", "partition"});
    VertexSpec spec;
    spec.where = where;
    spec.id = string_field(object, "id", where, true).value_or("");
    spec.x = number_field(object, "x", where, true).value_or(0.0);
    spec.y = number_field(object, "y", where, true).value_or(0.0);
    spec.orientation = number_field(object, "orientation", where, false);
    if (const auto kind = string_field(object, "kind", where, false)) {
      if (const auto known = vertex_kind_from_string(*kind)) {
        spec.kind = *known;
      } else {
        report(json_member_path(where, "kind"),
               "unknown vertex kind '" + *kind +
                   "' (expected waypoint, station, parking or charger)");
      }
    }
    spec.footprint = read_footprint(object, where);
    spec.restrictions = read_restrictions(object, where);
    spec.properties = read_properties(object, where);
    if (auto partition = string_field(object, "partition", where, false)) {
      spec.partition = std::move(*partition);
    }
    return spec;
  }

  std::optional<EdgeSpec> read_edge(const Json& object, const std::string& where) {
    if (!expect_object(object, where)) return std::nullopt;
    only_fields(object, where, {"id", "from", "to", "bidirectional", "length", "max_speed",
                                "footprint", "restrictions", "properties", "partition"});
    EdgeSpec spec;
    spec.where = where;
    spec.id = string_field(object, "id", where, true).value_or("");
    spec.from = string_field(object, "from", where, true).value_or("");
    spec.to = string_field(object, "to", where, true).value_or("");
    spec.bidirectional = bool_field(object, "bidirectional", where).value_or(false);
    spec.length = number_field(object, "length", where, false);
    spec.max_speed = number_field(object, "max_speed", where, true).value_or(0.0);
    spec.footprint = read_footprint(object, where);
    spec.restrictions = read_restrictions(object, where);
    spec.properties = read_properties(object, where);
    if (auto partition = string_field(object, "partition", where, false)) {
      spec.partition = std::move(*partition);
    }
    return spec;
  }

  Diagnostics diagnostics_;
};

Json point_json(const Point& point) { return Json::array({point.x(), point.y()}); }

Json footprint_json(const Polygon& footprint) {
  Json ring = Json::array();
  for (const auto& corner : footprint.outer()) ring.push_back(point_json(corner));
  return ring;
}

Json restrictions_json(const Restrictions& restrictions) {
  Json object = Json::object();
  const auto limit = [&](std::string_view key, const std::optional<double>& value) {
    if (value) object[std::string(key)] = *value;
  };
  limit("max_speed", restrictions.max_speed);
  limit("max_payload", restrictions.max_payload);
  if (!restrictions.allowed_vehicle_types.empty()) {
    object["allowed_vehicle_types"] = restrictions.allowed_vehicle_types;
  }
  if (!restrictions.forbidden_vehicle_types.empty()) {
    object["forbidden_vehicle_types"] = restrictions.forbidden_vehicle_types;
  }
  limit("max_vehicle_length", restrictions.max_vehicle_length);
  limit("max_vehicle_width", restrictions.max_vehicle_width);
  return object;
}

/// The members every entity may carry after its own fields.
void write_common(Json& object, const Polygon& footprint, bool footprint_generated,
                  const Restrictions& restrictions, const Properties& properties,
                  const std::string& partition) {
  if (!footprint_generated) object["footprint"] = footprint_json(footprint);
  if (restrictions != Restrictions{}) object["restrictions"] = restrictions_json(restrictions);
  if (!properties.empty()) {
    Json map = Json::object();
    for (const auto& [key, value] : properties) map[key] = value;
    object["properties"] = std::move(map);
  }
  object["partition"] = partition;
}

Json vertex_json(const Vertex& vertex) {
  Json object = Json::object();
  object["id"] = vertex.id;
  object["x"] = vertex.position.x();
  object["y"] = vertex.position.y();
  if (vertex.orientation) object["orientation"] = *vertex.orientation;
  object["kind"] = to_string(vertex.kind);
  write_common(object, vertex.footprint, vertex.footprint_generated, vertex.restrictions,
               vertex.properties, vertex.partition);
  return object;
}

Json edge_json(const Topology& topology, const Edge& edge) {
  Json object = Json::object();
  object["id"] = edge.id;
  object["from"] = topology.vertex(edge.from).id;
  object["to"] = topology.vertex(edge.to).id;
  object["bidirectional"] = edge.bidirectional;
  object["length"] = edge.length;
  object["max_speed"] = edge.max_speed;
  write_common(object, edge.footprint, edge.footprint_generated, edge.restrictions,
               edge.properties, edge.partition);
  return object;
}

/// One line of JSON; text that is not UTF-8 (possible only through the builder API) is
/// written with replacement characters rather than failing.
std::string dump(const Json& value) {
  return value.dump(-1, ' ', false, Json::error_handler_t::replace);
}

template <class Items, class ToJson>
void write_list(std::string& out, std::string_view key, const Items& items, ToJson to_json,
                bool last) {
  out += "  \"" + std::string(key) + "\": [";
  for (std::size_t i = 0; i < items.size(); ++i) {
    out += i == 0 ? "\n    " : ",\n    ";
    out += dump(to_json(items[i]));
  }
  out += items.empty() ? "]" : "\n  ]";
  out += last ? "\n" : ",\n";
}

}  // namespace

Result<Topology, Diagnostics> parse_topology_json(std::string_view text) {
  auto document = parse_json_document<Json>(text);
  if (!document) {
    Diagnostics problems;
    for (auto& problem : document.error()) {
      problems.push_back(Diagnostic{std::move(problem.where), std::move(problem.what)});
    }
    return unexpected(std::move(problems));
  }
  SpecReader reader;
  auto builder = reader.read_document(*document);
  // Structural problems first: the builder's checks on half-read specs would only add noise.
  if (!reader.diagnostics().empty()) return unexpected(std::move(reader.diagnostics()));
  return std::move(*builder).build();
}

Result<Topology, Diagnostics> load_topology_json(const std::filesystem::path& path) {
  auto text = read_text_file(path);
  if (!text) return unexpected(Diagnostics{{"", std::move(text).error().message}});
  return parse_topology_json(*text);
}

std::string write_topology_json(const Topology& topology) {
  const FootprintOptions& options = topology.footprint_options();
  Json footprint_options = Json::object();
  footprint_options["vertex_shape"] = options.vertex_disc ? "disc" : "square";
  footprint_options["vertex_radius"] = options.vertex_radius;
  footprint_options["disc_points"] = options.disc_points;
  footprint_options["edge_half_width"] = options.edge_half_width;

  std::string out = "{\n";
  out += "  \"name\": " + dump(Json(topology.name())) + ",\n";
  out += "  \"footprint_options\": " + dump(footprint_options) + ",\n";
  write_list(out, "vertices", topology.vertices(), vertex_json, false);
  write_list(
      out, "edges", topology.edges(),
      [&topology](const Edge& edge) { return edge_json(topology, edge); }, true);
  out += "}\n";
  return out;
}

}  // namespace drover::topology
