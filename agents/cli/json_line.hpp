#pragma once
// droverctl's --json output: one JSON value per line.

#include <string>

#include <nlohmann/json.hpp>

namespace drover::cli {

/// `json` on one line. Bytes that are not UTF-8 (a lock reason typed on a Latin-1
/// terminal, an id from an older tool) are replaced, so that the line stays valid JSON and
/// printing never fails after the work was done.
inline std::string json_line(const nlohmann::json& json) {
  return json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace drover::cli
