#include "bench/scenario.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "drover/common/text_file.hpp"

namespace drover::bench {

namespace {

std::vector<std::string_view> split_fields(std::string_view line) {
  // Fields are separated by tabs; lines without tabs are split on blanks.
  const bool tabs = line.find('\t') != std::string_view::npos;
  std::vector<std::string_view> fields;
  std::size_t begin = 0;
  while (begin <= line.size()) {
    std::size_t end = tabs ? line.find('\t', begin) : line.find_first_of(" \t", begin);
    if (end == std::string_view::npos) end = line.size();
    if (end > begin || tabs) fields.push_back(line.substr(begin, end - begin));
    begin = end + 1;
  }
  return fields;
}

template <class T>
bool parse_number(std::string_view text, T& value) {
  const auto* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  return ec == std::errc() && ptr == end;
}

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

}  // namespace

Result<std::vector<ScenarioTask>> parse_scenario(std::string_view text, const std::string& name) {
  std::vector<ScenarioTask> tasks;
  const auto bad = [&name](int line, const std::string& what) {
    return fail(ErrorCode::parse, fmt::format("{}:line {}: {}", name, line, what));
  };
  std::size_t position = 0;
  int line_number = 0;
  bool header_seen = false;
  while (position < text.size()) {
    std::size_t end = text.find('\n', position);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = trim(text.substr(position, end - position));
    position = end + 1;
    ++line_number;
    if (line.empty()) continue;
    if (!header_seen) {
      const auto fields = split_fields(line);
      double version = 0;
      if (fields.size() != 2 || fields[0] != "version" || !parse_number(fields[1], version)) {
        return bad(line_number, fmt::format("expected \"version 1\", got {}", printable_excerpt(line)));
      }
      if (version != 1) {
        return bad(line_number, fmt::format("unsupported version {}", printable_excerpt(fields[1])));
      }
      header_seen = true;
      continue;
    }
    const auto fields = split_fields(line);
    if (fields.size() != 9) {
      return bad(line_number, fmt::format("expected 9 fields (bucket, map, width, height, "
                                          "start x/y, goal x/y, optimal length), got {}",
                                          fields.size()));
    }
    ScenarioTask task;
    task.line = line_number;
    task.map = std::string(fields[1]);
    const struct {
      const char* what;
      std::string_view text;
      int* value;
    } integers[] = {{"bucket", fields[0], &task.bucket},     {"map width", fields[2], &task.map_width},
                    {"map height", fields[3], &task.map_height}, {"start x", fields[4], &task.start_x},
                    {"start y", fields[5], &task.start_y},   {"goal x", fields[6], &task.goal_x},
                    {"goal y", fields[7], &task.goal_y}};
    for (const auto& field : integers) {
      if (!parse_number(field.text, *field.value) || *field.value < 0) {
        return bad(line_number, fmt::format("{} {} is not a whole number from 0 to {}", field.what,
                                            printable_excerpt(field.text),
                                            std::numeric_limits<int>::max()));
      }
    }
    if (!parse_number(fields[8], task.optimal_length) || !std::isfinite(task.optimal_length) ||
        task.optimal_length < 0) {
      return bad(line_number, fmt::format("optimal length {} is not a finite number >= 0",
                                          printable_excerpt(fields[8])));
    }
    if (task.start_x >= task.map_width || task.goal_x >= task.map_width ||
        task.start_y >= task.map_height || task.goal_y >= task.map_height) {
      return bad(line_number, fmt::format("start ({},{}) or goal ({},{}) lies outside the {}x{} map",
                                          task.start_x, task.start_y, task.goal_x, task.goal_y,
                                          task.map_width, task.map_height));
    }
    tasks.push_back(std::move(task));
  }
  if (!header_seen) {
    return bad(std::max(line_number, 1), std::string(text.empty() ? "empty file" : "only blank lines") +
                                             " (expected \"version 1\")");
  }
  return tasks;
}

Result<std::vector<ScenarioTask>> load_scenario(const std::filesystem::path& path) {
  auto text = read_text_file(path);
  if (!text) return fail(ErrorCode::io, fmt::format("{}: {}", path.string(), text.error().message));
  return parse_scenario(*text, path.string());
}

}  // namespace drover::bench
