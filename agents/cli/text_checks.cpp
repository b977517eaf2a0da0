#include "agents/cli/text_checks.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "drover/common/identifier.hpp"

namespace drover::cli {

CLI::Validator identifier() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        auto problem = identifier_problem(input);
        if (!problem) return {};
        return input.empty() ? *problem : "'" + printable_identifier(input) + "' " + *problem;
      },
      "ID");
}

bool is_log_level(std::string_view level) {
  static constexpr std::array<std::string_view, 6> kLevels{"trace", "debug", "info", "warn", "error", "off"};
  return std::find(kLevels.begin(), kLevels.end(), level) != kLevels.end();
}

CLI::Validator log_level() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        return is_log_level(input) ? std::string() : "'" + input + "' is not one of trace, debug, info, warn, error, off";
      },
      "LEVEL");
}

CLI::Validator non_empty() {
  return CLI::Validator(
      [](std::string& input) -> std::string { return input.empty() ? "must not be empty" : std::string(); }, "");
}

}  // namespace drover::cli
