#pragma once
// Why a JSON text does not parse, in the words every loader prints: where ("line L,
// column C") and what, for topologies, launch files and vehicle profiles alike.

#include <exception>
#include <string>
#include <string_view>

namespace drover {

struct JsonSyntaxError {
  std::string where;  ///< "line L, column C" of the last character read; "" if unknown
  std::string what;   ///< "malformed JSON: ..." without nlohmann's exception tag
};

/// Describes why nlohmann refused `text`, from the exception its parse threw: a parse_error,
/// or out_of_range.406 for a number beyond double range (which carries no position, so the
/// text is scanned again to find it; that is the error path only).
/// \pre `error` was thrown by parsing exactly `text`.
JsonSyntaxError json_syntax_error(std::string_view text, const std::exception& error);

}  // namespace drover
