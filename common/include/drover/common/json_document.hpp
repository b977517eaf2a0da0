#pragma once
// Reading a JSON text that people write (topologies, launch files, vehicle profiles) as one
// document, strictly: what JSON or its parser lets through but a person never means is
// refused too, each problem said as where and what, in the words every loader prints.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "drover/common/result.hpp"

namespace drover {

/// One reason a JSON text is refused.
struct JsonProblem {
  /// "line L, column C" for malformed JSON and a NUL byte (nlohmann's count: lines and
  /// columns from 1, the column of the character the parse stopped at; a text cut short
  /// stops one past its end); the JSON path of a key given twice ("vertices[2].id");
  /// "" when there is no one place (the count of duplicates not named).
  std::string where;
  /// "malformed JSON: ...", "key given twice in the same object", "N more keys given twice".
  std::string what;

  friend bool operator==(const JsonProblem&, const JsonProblem&) = default;
};
using JsonProblems = std::vector<JsonProblem>;

/// Parses the whole of `text` as exactly one JSON document.
/// Refuses, beyond malformed JSON:
/// - a NUL byte anywhere: nlohmann's lexer takes one for the end of the input, so a
///   document followed by a NUL and anything at all parsed as if the rest were absent;
/// - a key given twice in one object: JSON allows it and nlohmann keeps the last value,
///   which would let a pasted or misspelt duplicate pass silently. The first 100 are named
///   by their path, the rest counted in one last problem (each path is as long as the
///   nesting is deep: naming every duplicate of a deeply nested file took minutes).
/// \return the document, or its problems: the one NUL byte or syntax error that stops the
///         parse (the first NUL), else every key given twice, in the order of the text.
/// Json is nlohmann::json or nlohmann::ordered_json (the two instantiated); ordered_json
/// keeps the text's order of keys.
template <class Json>
Result<Json, JsonProblems> parse_json_document(std::string_view text);

extern template Result<nlohmann::json, JsonProblems> parse_json_document<nlohmann::json>(
    std::string_view text);
extern template Result<nlohmann::ordered_json, JsonProblems>
parse_json_document<nlohmann::ordered_json>(std::string_view text);

/// The JSON path of member `key` of the value at path `where` ("" for the document itself),
/// as problems name places: "name", "vertices[2].id".
std::string json_member_path(std::string where, std::string_view key);

/// The JSON path of element `index` of the array at path `where`: "vertices[2]".
std::string json_element_path(std::string where, std::size_t index);

}  // namespace drover
