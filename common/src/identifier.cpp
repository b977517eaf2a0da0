#include "drover/common/identifier.hpp"

#include <fmt/format.h>

namespace drover {

namespace {

constexpr std::size_t kShownBytes = 40;

bool is_control(unsigned char c) { return c < 0x20 || c == 0x7f; }

}  // namespace

std::optional<std::string> identifier_problem(std::string_view id) {
  if (id.empty()) return "must not be empty";
  if (id.size() > kMaxIdentifierBytes) {
    return fmt::format("is {} bytes long, at most {} are allowed", id.size(), kMaxIdentifierBytes);
  }
  for (std::size_t i = 0; i < id.size(); ++i) {
    const auto c = static_cast<unsigned char>(id[i]);
    if (is_control(c)) return fmt::format("contains the control character 0x{:02x} at byte {}", c, i);
  }
  return std::nullopt;
}

std::string printable_identifier(std::string_view id) {
  std::string out;
  const std::string_view shown = id.substr(0, kShownBytes);
  for (const char ch : shown) {
    const auto c = static_cast<unsigned char>(ch);
    if (is_control(c)) {
      out += fmt::format("\\x{:02x}", c);
    } else {
      out += ch;
    }
  }
  if (shown.size() < id.size()) out += "...";
  return out;
}

Status check_identifier(std::string_view id, std::string_view what) {
  auto problem = identifier_problem(id);
  if (!problem) return {};
  if (id.empty()) return fail(ErrorCode::invalid_argument, fmt::format("{} {}", what, *problem));
  return fail(ErrorCode::invalid_argument, fmt::format("{} '{}' {}", what, printable_identifier(id), *problem));
}

}  // namespace drover
