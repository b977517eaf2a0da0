#pragma once
// The rule every identifier that travels as a DDS key obeys: agent, vehicle, order and
// entity ids. The generated types serialize a key into a buffer of 255 bytes per string,
// so a longer key cannot be published (Fast CDR throws); and a control character such as
// NUL would cut the id short on the wire, so that two different ids become one.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "drover/common/result.hpp"

namespace drover {

/// Longest identifier, in bytes (UTF-8 allowed).
inline constexpr std::size_t kMaxIdentifierBytes = 255;

/// \return what is wrong with `id` ("must not be empty", "is 300 bytes long, at most 255
///         are allowed", "contains the control character 0x00 at byte 6"), or nothing.
std::optional<std::string> identifier_problem(std::string_view id);

/// \return success, or invalid_argument "<what> '<id>' <problem>" (a long id shortened,
///         control characters escaped).
Status check_identifier(std::string_view id, std::string_view what);

/// `id` for a message: control characters as \xHH, cut after 40 bytes with "...".
std::string printable_identifier(std::string_view id);

}  // namespace drover
