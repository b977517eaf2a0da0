#pragma once
// Test topologies on a unit grid with the MovingAI importer's footprints: a vertex "x,y"
// owns its cell square, an edge "x,y-x2,y2" the rectangle between the two cell centres, one
// cell wide. So an edge conflicts with its end vertices and with the edges perpendicular to
// it at a shared vertex.

#include <string>
#include <utility>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "drover/topology/footprints.hpp"
#include "drover/topology/topology_builder.hpp"

namespace drover::carp::test {

inline std::string cell_id(int x, int y) { return fmt::format("{},{}", x, y); }
inline std::string edge_id(int x1, int y1, int x2, int y2) {
  return fmt::format("{},{}-{},{}", x1, y1, x2, y2);
}

struct EdgeOptions {
  double length = 1.0;        ///< metres (need not match the geometry)
  double max_speed = 1.0;
  bool bidirectional = true;  ///< false: only (x1,y1) -> (x2,y2)
  topology::Restrictions restrictions = {};
};

class GridBuilder {
 public:
  explicit GridBuilder(std::string name = "grid") : builder_(std::move(name)) {}

  GridBuilder& cell(int x, int y, topology::Restrictions restrictions = {}) {
    topology::VertexSpec spec;
    spec.id = cell_id(x, y);
    spec.x = x;
    spec.y = y;
    spec.footprint = topology::axis_aligned_rectangle(x - 0.5, y - 0.5, x + 0.5, y + 0.5);
    spec.restrictions = std::move(restrictions);
    builder_.add_vertex(std::move(spec));
    return *this;
  }
  GridBuilder& edge(int x1, int y1, int x2, int y2, EdgeOptions options = {}) {
    topology::EdgeSpec spec;
    spec.id = edge_id(x1, y1, x2, y2);
    spec.from = cell_id(x1, y1);
    spec.to = cell_id(x2, y2);
    spec.bidirectional = options.bidirectional;
    spec.length = options.length;
    spec.max_speed = options.max_speed;
    spec.footprint = topology::segment_rectangle(topology::Point(x1, y1),
                                                 topology::Point(x2, y2), 0.5);
    spec.restrictions = std::move(options.restrictions);
    builder_.add_edge(std::move(spec));
    return *this;
  }
  /// A straight row of `count` cells at y = 0, joined left to right.
  GridBuilder& corridor(int count, EdgeOptions options = {}) {
    for (int x = 0; x < count; ++x) cell(x, 0);
    for (int x = 0; x + 1 < count; ++x) edge(x, 0, x + 1, 0, options);
    return *this;
  }

  topology::Topology build() {
    auto built = std::move(builder_).build();
    if (!built) {
      std::string problems;
      for (const auto& d : built.error()) problems += d.where + ": " + d.what + "\n";
      ADD_FAILURE() << "test topology does not build:\n" << problems;
      return topology::Topology{};
    }
    return std::move(built).value();
  }

 private:
  topology::TopologyBuilder builder_;
};

}  // namespace drover::carp::test
