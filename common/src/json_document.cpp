#include "drover/common/json_document.hpp"

#include <algorithm>
#include <exception>
#include <functional>
#include <optional>
#include <set>
#include <utility>

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

/// Why nlohmann refused `text`, from the exception its parse threw: a parse_error, or
/// out_of_range.406 for a number beyond double range (which carries no position, so the
/// text is scanned again to find it; that is the error path only).
/// \pre `error` was thrown by parsing exactly `text`.
JsonProblem syntax_problem(std::string_view text, const std::exception& error) {
  const auto offset = failure_offset(text);
  return JsonProblem{offset ? line_and_column(text, *offset) : std::string(),
                     "malformed JSON: " + detail_of(error.what())};
}

/// Watches the parser for keys given twice in one object, tracking the JSON path of the
/// value being parsed so that a duplicate can be named.
template <class Json>
class DuplicateKeyWatch {
 public:
  JsonProblems& duplicates() { return duplicates_; }

  bool operator()(int /*depth*/, typename Json::parse_event_t event, Json& parsed) {
    using Event = typename Json::parse_event_t;
    switch (event) {
      case Event::object_start:
      case Event::array_start:
        count_element();
        frames_.push_back(Frame{event == Event::object_start, {}, 0, {}});
        break;
      case Event::object_end:
      case Event::array_end:
        if (!frames_.empty()) frames_.pop_back();
        break;
      case Event::key: {
        Frame& object = frames_.back();
        object.key = parsed.template get<std::string>();
        if (!object.keys.insert(object.key).second) report_duplicate();
        break;
      }
      case Event::value:
        count_element();
        break;
    }
    return true;
  }

 private:
  struct Frame {
    bool object = false;
    std::string key;              // objects: the key being parsed
    std::size_t elements = 0;     // arrays: elements started so far
    std::set<std::string> keys;   // objects: keys seen
  };

  void count_element() {
    if (!frames_.empty() && !frames_.back().object) ++frames_.back().elements;
  }

  /// Reports the key just read by its path, up to kMaxNamed of them, then counts the rest
  /// in one last problem.
  void report_duplicate() {
    constexpr std::size_t kMaxNamed = 100;
    if (duplicates_.size() < kMaxNamed) {
      duplicates_.push_back(JsonProblem{path(), "key given twice in the same object"});
      return;
    }
    ++unnamed_;
    if (duplicates_.size() == kMaxNamed) duplicates_.push_back(JsonProblem{});
    duplicates_.back().what = std::to_string(unnamed_) + " more keys given twice";
  }

  std::string path() const {
    std::string where;
    for (const Frame& frame : frames_) {
      where = frame.object ? json_member_path(std::move(where), frame.key)
                           : json_element_path(std::move(where),
                                               frame.elements == 0 ? 0 : frame.elements - 1);
    }
    return where;
  }

  std::vector<Frame> frames_;
  JsonProblems duplicates_;
  std::size_t unnamed_ = 0;  // duplicates found after kMaxNamed were named
};

}  // namespace

template <class Json>
Result<Json, JsonProblems> parse_json_document(std::string_view text) {
  // Before the parse, which would stop at the NUL as if the text ended there.
  if (const std::size_t nul = text.find('\0'); nul != std::string_view::npos) {
    return unexpected(JsonProblems{JsonProblem{
        line_and_column(text, nul + 1), "malformed JSON: NUL byte (a JSON text cannot contain one)"}});
  }
  DuplicateKeyWatch<Json> watch;
  Json document;
  try {
    document = Json::parse(text.begin(), text.end(), std::ref(watch));
  } catch (const typename Json::exception& error) {
    return unexpected(JsonProblems{syntax_problem(text, error)});
  }
  if (!watch.duplicates().empty()) return unexpected(std::move(watch.duplicates()));
  return document;
}

template Result<nlohmann::json, JsonProblems> parse_json_document<nlohmann::json>(
    std::string_view text);
template Result<nlohmann::ordered_json, JsonProblems>
parse_json_document<nlohmann::ordered_json>(std::string_view text);

std::string json_member_path(std::string where, std::string_view key) {
  if (!where.empty()) where += '.';
  where += key;
  return where;
}

std::string json_element_path(std::string where, std::size_t index) {
  where += '[';
  where += std::to_string(index);
  where += ']';
  return where;
}

}  // namespace drover
