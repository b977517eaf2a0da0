#pragma once
// Importer for MovingAI grid maps (https://movingai.com/benchmarks/formats.html):
//
//   type octile
//   height H
//   width W
//   map
//   H rows of W characters
//
// Passable cells are '.', 'G' and 'S'; '@', 'O', 'T' (trees) and 'W' (water, which a ground
// vehicle cannot cross) are impassable. Every passable cell becomes a vertex with id "x,y"
// (x the column, y the row, both from 0) at position (x * cell_size, y * cell_size): the
// y axis is NOT flipped, so y grows downwards as the rows do. Every pair of 4-neighbouring
// passable cells becomes one bidirectional edge "x,y-x2,y2", from the cell to its right
// (x + 1) or lower (y + 1) neighbour, of length cell_size.
//
// Footprints are given explicitly: a vertex has its cell square; an edge has the rectangle
// between its two cell centres, one cell wide. So an edge conflicts with its two end
// vertices and with the edges perpendicular to it at a shared vertex, while consecutive
// straight edges and parallel neighbouring edges only touch.

#include <filesystem>
#include <string>
#include <string_view>

#include "drover/common/result.hpp"
#include "drover/topology/model.hpp"
#include "drover/topology/topology_builder.hpp"

namespace drover::topology {

struct MovingAiOptions {
  double cell_size = 1.0;  ///< m, the side of a cell; > 0
  double max_speed = 1.0;  ///< m/s, of every edge; > 0
  std::string partition = "main";
};

/// An imported map with the size its header gives (a scenario names the size it was made
/// for; the topology alone cannot tell it when a border row or column is blocked).
struct MovingAiGrid {
  Topology topology;
  int width = 0;   ///< cells per row
  int height = 0;  ///< rows
};

/// Imports the map at `path` with its size; the topology is named after the file's stem.
/// \return as load_movingai_map.
Result<MovingAiGrid, Diagnostics> load_movingai_grid(const std::filesystem::path& path,
                                                     const MovingAiOptions& options = {});

/// Imports the map at `path`; the topology is named after the file's stem.
/// \return the topology, or every problem found: an unreadable or empty file (where ""),
///         header problems, rows of the wrong count or length and unknown characters
///         (where "line N"), bad options (where "options.cell_size" / "options.max_speed").
Result<Topology, Diagnostics> load_movingai_map(const std::filesystem::path& path,
                                                const MovingAiOptions& options = {});

/// Same as load_movingai_map, from the text of a map.
Result<Topology, Diagnostics> parse_movingai_map(std::string_view text, std::string name,
                                                 const MovingAiOptions& options = {});

}  // namespace drover::topology
