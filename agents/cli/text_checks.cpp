#include "agents/cli/text_checks.hpp"

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

CLI::Validator non_empty() {
  return CLI::Validator(
      [](std::string& input) -> std::string { return input.empty() ? "must not be empty" : std::string(); }, "");
}

}  // namespace drover::cli
