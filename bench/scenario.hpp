#pragma once
// MovingAI scenario files (https://movingai.com/benchmarks/formats.html): a "version 1"
// line, then one task per line, tab-separated:
//   bucket  map  map-width  map-height  start-x  start-y  goal-x  goal-y  optimal-length

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "drover/common/result.hpp"

namespace drover::bench {

struct ScenarioTask {
  int bucket = 0;
  std::string map;        ///< the map file the task was made for
  int map_width = 0;
  int map_height = 0;
  int start_x = 0, start_y = 0;  ///< column, row
  int goal_x = 0, goal_y = 0;
  double optimal_length = 0;     ///< with the scenario's own (octile) moves
  int line = 0;                  ///< 1-based line in the file
};

/// Parses scenario text; `name` prefixes error messages.
/// \return the tasks in file order, or a parse error "NAME:line N: what is wrong".
Result<std::vector<ScenarioTask>> parse_scenario(std::string_view text, const std::string& name);

/// Reads and parses a scenario file. \return the tasks, or io / parse errors naming the file.
Result<std::vector<ScenarioTask>> load_scenario(const std::filesystem::path& path);

}  // namespace drover::bench
