#include "drover/common/json_syntax.hpp"

#include <algorithm>
#include <optional>

#include <nlohmann/json.hpp>

namespace drover {

namespace {

/// The number of characters the parser had read when it failed, from a SAX handler that
/// accepts every value: the one interface through which nlohmann hands out that offset.
std::optional<std::size_t> failure_offset(std::string_view text) {
  struct Locator : nlohmann::json_sax<nlohmann::json> {
    std::optional<std::size_t> offset;
    bool null() override { return true; }
    bool boolean(bool) override { return true; }
    bool number_integer(number_integer_t) override { return true; }
    bool number_unsigned(number_unsigned_t) override { return true; }
    bool number_float(number_float_t, const string_t&) override { return true; }
    bool string(string_t&) override { return true; }
    bool binary(binary_t&) override { return true; }
    bool start_object(std::size_t) override { return true; }
    bool key(string_t&) override { return true; }
    bool end_object() override { return true; }
    bool start_array(std::size_t) override { return true; }
    bool end_array() override { return true; }
    bool parse_error(std::size_t position, const std::string&,
                     const nlohmann::detail::exception&) override {
      offset = position;
      return false;
    }
  } locator;
  nlohmann::json::sax_parse(text.begin(), text.end(), &locator);
  return locator.offset;
}

/// "line L, column C" as nlohmann counts them: lines from 1, the column of the last
/// character read (0 right after a line break). At the end of the text the offset is one
/// past it: the end counts as a character read.
std::string line_and_column(std::string_view text, std::size_t offset) {
  const std::string_view read = text.substr(0, std::min(offset, text.size()));
  const std::size_t last_break = read.rfind('\n');
  const std::size_t line_start = last_break == std::string_view::npos ? 0 : last_break + 1;
  return "line " + std::to_string(std::count(read.begin(), read.end(), '\n') + 1) + ", column " +
         std::to_string(offset - line_start);
}

/// nlohmann's message without "[json.exception.KIND.N] " and "parse error at ...: ".
std::string detail_of(std::string_view message) {
  if (message.rfind("[json.exception.", 0) == 0) {
    const auto tag_end = message.find("] ");
    if (tag_end != std::string_view::npos) message.remove_prefix(tag_end + 2);
  }
  constexpr std::string_view kParseError = "parse error";
  if (message.rfind(kParseError, 0) == 0) {
    const auto colon = message.find(": ");
    if (colon != std::string_view::npos) message.remove_prefix(colon + 2);
  }
  return std::string(message);
}

}  // namespace

JsonSyntaxError json_syntax_error(std::string_view text, const std::exception& error) {
  const auto offset = failure_offset(text);
  return JsonSyntaxError{offset ? line_and_column(text, *offset) : std::string(),
                         "malformed JSON: " + detail_of(error.what())};
}

}  // namespace drover
