// parse_json_document, which every loader of a JSON file people write uses: what it refuses
// beyond malformed JSON (NUL bytes, keys given twice), and how it names where.

#include "drover/common/json_document.hpp"

#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace drover {
namespace {

std::string dump(const JsonProblems& problems) {
  std::string text;
  for (const auto& problem : problems) text += problem.where + ": " + problem.what + "\n";
  return text;
}

/// The problems of a text that must be refused.
JsonProblems problems_of(std::string_view text) {
  auto parsed = parse_json_document<nlohmann::json>(text);
  EXPECT_FALSE(parsed.has_value()) << "accepted: " << text;
  return parsed ? JsonProblems{} : parsed.error();
}

constexpr std::string_view kNul = "malformed JSON: NUL byte (a JSON text cannot contain one)";
constexpr std::string_view kTwice = "key given twice in the same object";

TEST(JsonDocument, ParsesOneDocumentKeepingOrderWhenAsked) {
  const auto plain = parse_json_document<nlohmann::json>(R"({"b": [1, {"c": null}], "a": "x"})");
  ASSERT_TRUE(plain.has_value()) << dump(plain.error());
  EXPECT_EQ(plain->dump(), R"({"a":"x","b":[1,{"c":null}]})");
  const auto ordered = parse_json_document<nlohmann::ordered_json>(R"({"b": 1, "a": 2})");
  ASSERT_TRUE(ordered.has_value()) << dump(ordered.error());
  EXPECT_EQ(ordered->dump(), R"({"b":1,"a":2})");
  // One key in several objects is no duplicate.
  EXPECT_TRUE(parse_json_document<nlohmann::json>(R"([{"k": 1}, {"k": {"k": 2}}])"));
}

TEST(JsonDocument, MalformedJsonNamesLineAndColumn) {
  EXPECT_EQ(problems_of("{\"a\": 1,\n \"b\": ]}"),
            (JsonProblems{{"line 2, column 7",
                           "malformed JSON: syntax error while parsing value - unexpected ']'; "
                           "expected '[', '{', or a literal"}}));
  // Exactly one document: a second one after it is malformed.
  const auto two = problems_of("{} {}");
  ASSERT_EQ(two.size(), 1u);
  EXPECT_EQ(two[0].where, "line 1, column 4");
  // A number beyond double range carries no position from nlohmann: it is found again.
  EXPECT_EQ(problems_of("[1,\n 1e400]"),
            (JsonProblems{{"line 2, column 6", "malformed JSON: number overflow parsing '1e400'"}}));
}

// nlohmann's lexer takes a NUL for the end of the input: "{...}\0rest" parsed as "{...}".
TEST(JsonDocument, NulByteIsRefusedAtItsLineAndColumn) {
  using namespace std::string_literals;
  EXPECT_EQ(problems_of("{\"a\": 1}\0garbage"s), (JsonProblems{{"line 1, column 9", std::string(kNul)}}));
  EXPECT_EQ(problems_of("{\"a\": 1,\n  \0\"b\": 2}"s), (JsonProblems{{"line 2, column 3", std::string(kNul)}}));
  // Inside a string, at the start and as the whole text: the first NUL is named.
  EXPECT_EQ(problems_of("[\"a\0\", \0]"s), (JsonProblems{{"line 1, column 4", std::string(kNul)}}));
  EXPECT_EQ(problems_of("\0{}"s), (JsonProblems{{"line 1, column 1", std::string(kNul)}}));
  EXPECT_EQ(problems_of("\0"s), (JsonProblems{{"line 1, column 1", std::string(kNul)}}));
  // An escaped NUL is a character of a string, not a NUL byte of the text.
  const auto escaped = parse_json_document<nlohmann::json>(R"(["a\u0000b"])");
  ASSERT_TRUE(escaped.has_value()) << dump(escaped.error());
  EXPECT_EQ((*escaped)[0].get<std::string>(), std::string("a\0b", 3));
}

TEST(JsonDocument, KeysGivenTwiceAreNamedByTheirPathInTextOrder) {
  EXPECT_EQ(problems_of(R"({"b": {"c": [0, {"d": 1, "e": 2, "d": 3}]}, "a": 1, "b": 2, "f": [[{"g": 1, "g": 1}]]})"),
            (JsonProblems{{"b.c[1].d", std::string(kTwice)},
                          {"b", std::string(kTwice)},
                          {"f[0][0].g", std::string(kTwice)}}));
  EXPECT_EQ(problems_of(R"([{"k": 1, "k": 1, "k": 1}])"),
            (JsonProblems{{"[0].k", std::string(kTwice)}, {"[0].k", std::string(kTwice)}}));
  // ordered_json, whose objects are not maps, is watched the same way.
  const auto ordered = parse_json_document<nlohmann::ordered_json>(R"({"x": 1, "x": 2})");
  ASSERT_FALSE(ordered.has_value());
  EXPECT_EQ(ordered.error(), (JsonProblems{{"x", std::string(kTwice)}}));
}

TEST(JsonDocument, KeysGivenTwiceAreNamedUpToAHundredThenCounted) {
  std::string text = "{";
  for (int key = 0; key < 150; ++key) {
    const std::string member = "\"k" + std::to_string(key) + "\": 0";
    text += (key == 0 ? "" : ", ") + member + ", " + member;
  }
  text += "}";
  const auto problems = problems_of(text);
  ASSERT_EQ(problems.size(), 101u) << dump(problems);
  EXPECT_EQ(problems[0], (JsonProblem{"k0", std::string(kTwice)}));
  EXPECT_EQ(problems[99], (JsonProblem{"k99", std::string(kTwice)}));
  EXPECT_EQ(problems[100], (JsonProblem{"", "50 more keys given twice"}));
}

TEST(JsonDocument, PathsJoinMembersAndElements) {
  EXPECT_EQ(json_member_path("", "name"), "name");
  EXPECT_EQ(json_member_path("vertices[2]", "id"), "vertices[2].id");
  EXPECT_EQ(json_element_path("vertices", 2), "vertices[2]");
  EXPECT_EQ(json_element_path("", 0), "[0]");
}

}  // namespace
}  // namespace drover
