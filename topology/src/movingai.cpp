#include "drover/topology/movingai.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "drover/common/text_file.hpp"
#include "drover/topology/footprints.hpp"

namespace drover::topology {

namespace {

/// Below this cell size, overlaps shrink under kOverlapAreaEpsilon and vanish.
constexpr double kMinCellSize = 0.01;
constexpr std::size_t kHeaderLines = 4;
constexpr int kMaxSide = 1'000'000;

std::string line_name(std::size_t index) { return "line " + std::to_string(index + 1); }

/// Lines without their terminators ("\n" or "\r\n"); a final terminator ends the last line
/// rather than starting an empty one.
std::vector<std::string_view> split_lines(std::string_view text) {
  std::vector<std::string_view> lines;
  while (!text.empty()) {
    const auto end = text.find('\n');
    std::string_view line = text.substr(0, end);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back(line);
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  return lines;
}

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> found;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) found.push_back(line.substr(start, i - start));
  }
  return found;
}

bool passable(char cell) { return cell == '.' || cell == 'G' || cell == 'S'; }
bool impassable(char cell) { return cell == '@' || cell == 'O' || cell == 'T' || cell == 'W'; }

struct Grid {
  int width = 0;
  int height = 0;
  std::vector<std::string_view> rows;
};

class MapReader {
 public:
  explicit MapReader(std::string_view text) : lines_(split_lines(text)) {}

  Diagnostics& diagnostics() { return diagnostics_; }

  /// The grid, or nullopt when the header is broken (the rows cannot be checked then).
  std::optional<Grid> read() {
    Grid grid;
    if (const auto type = header_line(0, "type octile")) {
      if (type->size() != 2 || (*type)[0] != "type" || (*type)[1] != "octile") {
        report(0, "expected 'type octile', got " + printable_excerpt(lines_[0]));
      }
    }
    // Height and width, in this order by convention; either order is accepted.
    std::optional<int> height;
    std::optional<int> width;
    bool height_seen = false;
    bool width_seen = false;
    for (std::size_t index = 1; index <= 2; ++index) {
      const auto line = header_line(index, index == 1 ? "height H" : "width W");
      if (!line) continue;
      const bool is_height = line->size() == 2 && (*line)[0] == "height";
      const bool is_width = line->size() == 2 && (*line)[0] == "width";
      if (!is_height && !is_width) {
        report(index, "expected 'height H' or 'width W', got " + printable_excerpt(lines_[index]));
        continue;
      }
      bool& seen = is_height ? height_seen : width_seen;
      if (seen) {
        report(index, std::string("'") + (is_height ? "height" : "width") + "' given twice");
        continue;
      }
      seen = true;
      (is_height ? height : width) = side((*line)[1], index);
    }
    if (const auto map = header_line(3, "map")) {
      if (map->size() != 1 || (*map)[0] != "map") {
        report(3, "expected 'map', got " + printable_excerpt(lines_[3]));
      }
    }
    if (lines_.size() >= kHeaderLines) {
      if (!height_seen) report(1, "the header gives no height");
      if (!width_seen) report(2, "the header gives no width");
    }
    if (!diagnostics_.empty() || !height || !width) return std::nullopt;

    grid.height = *height;
    grid.width = *width;
    grid.rows.assign(lines_.begin() + kHeaderLines, lines_.end());
    while (!grid.rows.empty() && grid.rows.back().empty()) grid.rows.pop_back();
    check_rows(grid);
    if (!diagnostics_.empty()) return std::nullopt;
    return grid;
  }

 private:
  void report(std::size_t line_index, std::string what) {
    diagnostics_.push_back(Diagnostic{line_name(line_index), std::move(what)});
  }

  /// The words of header line `index`, or nullopt (reported) when the file ends before it.
  std::optional<std::vector<std::string_view>> header_line(std::size_t index,
                                                           std::string_view expected) {
    if (index < lines_.size()) return words(lines_[index]);
    if (!ended_early_) {
      report(index, "the file ends in the header (expected '" + std::string(expected) + "')");
      ended_early_ = true;
    }
    return std::nullopt;
  }

  std::optional<int> side(std::string_view text, std::size_t index) {
    int value = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc{} || end != text.data() + text.size() || value <= 0 ||
        value > kMaxSide) {
      report(index, "expected a whole number from 1 to " + std::to_string(kMaxSide) +
                        ", got " + printable_excerpt(text));
      return std::nullopt;
    }
    return value;
  }

  void check_rows(const Grid& grid) {
    const auto expected_rows = static_cast<std::size_t>(grid.height);
    for (std::size_t row = 0; row < grid.rows.size() && row < expected_rows; ++row) {
      const std::size_t index = kHeaderLines + row;
      const std::string_view cells = grid.rows[row];
      if (cells.size() != static_cast<std::size_t>(grid.width)) {
        report(index, "expected " + std::to_string(grid.width) + " cells, found " +
                          std::to_string(cells.size()));
      }
      for (std::size_t column = 0; column < cells.size(); ++column) {
        if (passable(cells[column]) || impassable(cells[column])) continue;
        report(index, "unexpected character " + printable_excerpt(cells.substr(column, 1)) +
                          " at column " + std::to_string(column + 1) +
                          " (expected . G S passable, @ O T W impassable)");
        break;  // one problem per row is enough to find it
      }
    }
    if (grid.rows.size() != expected_rows) {
      const std::size_t at = kHeaderLines + std::min(grid.rows.size(), expected_rows);
      report(at, "expected " + std::to_string(grid.height) + " map rows, found " +
                     std::to_string(grid.rows.size()));
    }
  }

  std::vector<std::string_view> lines_;
  Diagnostics diagnostics_;
  bool ended_early_ = false;
};

std::string cell_id(int x, int y) { return std::to_string(x) + "," + std::to_string(y); }

Diagnostics check_options(const MovingAiOptions& options) {
  Diagnostics problems;
  if (!std::isfinite(options.cell_size) || options.cell_size < kMinCellSize) {
    problems.push_back(
        {"options.cell_size", "must be a finite number of at least 0.01 (metres)"});
  }
  if (!std::isfinite(options.max_speed) || options.max_speed <= 0) {
    problems.push_back({"options.max_speed", "must be a positive finite number (m/s)"});
  }
  if (options.partition.empty()) problems.push_back({"options.partition", "must not be empty"});
  return problems;
}

Result<MovingAiGrid, Diagnostics> build_grid(const Grid& grid, std::string name,
                                             const MovingAiOptions& options) {
  const double cell = options.cell_size;
  const double half = cell / 2;
  // The last cell's centre (a vertex) must stay within the coordinates a topology allows,
  // and its footprint, half a cell further, within those of corners.
  const int side = std::max(grid.width, grid.height);
  double largest = kMaxCornerCoordinate / (side - 0.5);
  if (side > 1) largest = std::min(largest, kMaxCoordinate / (side - 1));
  if (cell > largest) {
    std::ostringstream what;
    // Rounded down, so that the size suggested passes.
    what << std::fixed << std::setprecision(3) << "must be at most "
         << std::floor(largest * 1000) / 1000 << " (metres) for a map " << side
         << " cells wide or high: its cells must lie within 1000000 m of the origin";
    return unexpected(Diagnostics{{"options.cell_size", what.str()}});
  }
  const auto open = [&grid](int x, int y) {
    return x < grid.width && y < grid.height && passable(grid.rows[y][x]);
  };
  TopologyBuilder builder(std::move(name));
  for (int y = 0; y < grid.height; ++y) {
    for (int x = 0; x < grid.width; ++x) {
      if (!open(x, y)) continue;
      const double cx = x * cell;
      const double cy = y * cell;
      VertexSpec vertex;
      vertex.id = cell_id(x, y);
      vertex.x = cx;
      vertex.y = cy;
      vertex.footprint = axis_aligned_rectangle(cx - half, cy - half, cx + half, cy + half);
      vertex.partition = options.partition;
      builder.add_vertex(std::move(vertex));

      // One edge to the right and one downwards: every neighbouring pair exactly once.
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
        if (!open(x + dx, y + dy)) continue;
        EdgeSpec edge;
        edge.id = cell_id(x, y) + "-" + cell_id(x + dx, y + dy);
        edge.from = cell_id(x, y);
        edge.to = cell_id(x + dx, y + dy);
        edge.bidirectional = true;
        edge.length = cell;
        edge.max_speed = options.max_speed;
        edge.footprint = dx == 1 ? axis_aligned_rectangle(cx, cy - half, cx + cell, cy + half)
                                 : axis_aligned_rectangle(cx - half, cy, cx + half, cy + cell);
        edge.partition = options.partition;
        builder.add_edge(std::move(edge));
      }
    }
  }
  auto topology = std::move(builder).build();
  if (!topology) return unexpected(std::move(topology).error());
  return MovingAiGrid{std::move(topology).value(), grid.width, grid.height};
}

Result<MovingAiGrid, Diagnostics> parse_movingai_grid(std::string_view text, std::string name,
                                                      const MovingAiOptions& options) {
  if (auto problems = check_options(options); !problems.empty()) {
    return unexpected(std::move(problems));
  }
  MapReader reader(text);
  const auto grid = reader.read();
  if (!grid) return unexpected(std::move(reader.diagnostics()));
  return build_grid(*grid, std::move(name), options);
}

Result<Topology, Diagnostics> only_topology(Result<MovingAiGrid, Diagnostics> grid) {
  if (!grid) return unexpected(std::move(grid).error());
  return std::move(grid->topology);
}

}  // namespace

Result<Topology, Diagnostics> parse_movingai_map(std::string_view text, std::string name,
                                                 const MovingAiOptions& options) {
  return only_topology(parse_movingai_grid(text, std::move(name), options));
}

Result<MovingAiGrid, Diagnostics> load_movingai_grid(const std::filesystem::path& path,
                                                     const MovingAiOptions& options) {
  auto text = read_text_file(path);
  if (!text) return unexpected(Diagnostics{{"", std::move(text).error().message}});
  return parse_movingai_grid(*text, path.stem().string(), options);
}

Result<Topology, Diagnostics> load_movingai_map(const std::filesystem::path& path,
                                                const MovingAiOptions& options) {
  return only_topology(load_movingai_grid(path, options));
}

}  // namespace drover::topology
