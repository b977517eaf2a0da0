#pragma once
// Builds a validated Topology from specs (what a file or an importer read). Validation
// reports every problem it finds, each with where it is, and builds nothing on error.

#include <optional>
#include <string>
#include <vector>

#include "drover/common/result.hpp"
#include "drover/topology/model.hpp"

namespace drover::topology {

/// One problem found in input: `where` names the place (a JSON path such as
/// "vertices[3].id", or "line 4"), `what` says what is wrong.
struct Diagnostic {
  std::string where;
  std::string what;

  friend bool operator==(const Diagnostic&, const Diagnostic&) = default;
};
using Diagnostics = std::vector<Diagnostic>;

/// How every tool prints a problem in `file`: "FILE:WHERE: WHAT", or "FILE: WHAT" when the
/// problem has no place (the file as a whole: missing, empty, a directory).
std::string diagnostic_text(const std::string& file, const Diagnostic& problem);

struct VertexSpec {
  std::string id;
  double x = 0;
  double y = 0;
  std::optional<double> orientation;
  VertexKind kind = VertexKind::waypoint;
  std::optional<Polygon> footprint;  ///< generated when absent
  Restrictions restrictions;
  Properties properties;
  std::string partition = "main";
  std::string where;  ///< location in the source, prefixed to diagnostics (e.g. "vertices[3]")
};

struct EdgeSpec {
  std::string id;
  std::string from;
  std::string to;
  bool bidirectional = false;
  std::optional<double> length;  ///< metres; the distance between the vertices when absent
  double max_speed = 1.0;        ///< m/s
  std::optional<Polygon> footprint;
  Restrictions restrictions;
  Properties properties;
  std::string partition = "main";
  std::string where;
};

class TopologyBuilder {
 public:
  explicit TopologyBuilder(std::string name, FootprintOptions options = {});

  void add_vertex(VertexSpec vertex);
  void add_edge(EdgeSpec edge);

  /// Validates everything (ids unique across vertices and edges, edges name known vertices,
  /// lengths and speeds positive and finite, given footprints valid polygons), generates
  /// missing footprints, computes conflict sets with an R-tree, and returns the topology.
  /// \return the topology, or every problem found (nothing is built then).
  Result<Topology, Diagnostics> build() &&;

 private:
  std::string name_;
  FootprintOptions options_;
  std::vector<VertexSpec> vertices_;
  std::vector<EdgeSpec> edges_;
};

}  // namespace drover::topology
