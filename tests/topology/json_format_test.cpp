// The JSON topology format: loading good and bad files, and write/load round trips.

#include "drover/topology/json_format.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "drover/topology/movingai.hpp"

namespace drover::topology {
namespace {

std::filesystem::path data_file(const std::string& name) {
  const char* source = std::getenv("DROVER_SOURCE_DIR");
  return std::filesystem::path(source != nullptr ? source : ".") / "tests" / "data" / name;
}

std::string dump(const Diagnostics& diagnostics) {
  std::string text;
  for (const auto& d : diagnostics) text += d.where + ": " + d.what + "\n";
  return text;
}

Diagnostics errors_of(const Result<Topology, Diagnostics>& result) {
  EXPECT_FALSE(result.has_value()) << "invalid input was accepted";
  return result ? Diagnostics{} : result.error();
}

bool has_diagnostic(const Diagnostics& diagnostics, std::string_view where,
                    std::string_view what_part) {
  return std::any_of(diagnostics.begin(), diagnostics.end(), [&](const Diagnostic& d) {
    return d.where == where && d.what.find(what_part) != std::string::npos;
  });
}

bool same_polygon(const Polygon& a, const Polygon& b) {
  return a.outer().size() == b.outer().size() &&
         std::equal(a.outer().begin(), a.outer().end(), b.outer().begin(),
                    [](const Point& p, const Point& q) { return p.x() == q.x() && p.y() == q.y(); });
}

/// Every field, footprint, conflict set and move of two topologies is equal.
void expect_same_topology(const Topology& a, const Topology& b) {
  EXPECT_EQ(a.name(), b.name());
  ASSERT_EQ(a.vertex_count(), b.vertex_count());
  ASSERT_EQ(a.edge_count(), b.edge_count());
  EXPECT_EQ(a.footprint_options().vertex_disc, b.footprint_options().vertex_disc);
  EXPECT_EQ(a.footprint_options().vertex_radius, b.footprint_options().vertex_radius);
  EXPECT_EQ(a.footprint_options().disc_points, b.footprint_options().disc_points);
  EXPECT_EQ(a.footprint_options().edge_half_width, b.footprint_options().edge_half_width);
  for (std::size_t i = 0; i < a.vertex_count(); ++i) {
    const Vertex& v = a.vertices()[i];
    const Vertex& w = b.vertices()[i];
    SCOPED_TRACE("vertex " + v.id);
    EXPECT_EQ(v.id, w.id);
    EXPECT_EQ(v.position.x(), w.position.x());
    EXPECT_EQ(v.position.y(), w.position.y());
    EXPECT_EQ(v.orientation, w.orientation);
    EXPECT_EQ(v.kind, w.kind);
    EXPECT_TRUE(same_polygon(v.footprint, w.footprint));
    EXPECT_EQ(v.footprint_generated, w.footprint_generated);
    EXPECT_EQ(v.restrictions, w.restrictions);
    EXPECT_EQ(v.properties, w.properties);
    EXPECT_EQ(v.partition, w.partition);
  }
  for (std::size_t i = 0; i < a.edge_count(); ++i) {
    const Edge& e = a.edges()[i];
    const Edge& f = b.edges()[i];
    SCOPED_TRACE("edge " + e.id);
    EXPECT_EQ(e.id, f.id);
    EXPECT_EQ(e.from, f.from);
    EXPECT_EQ(e.to, f.to);
    EXPECT_EQ(e.bidirectional, f.bidirectional);
    EXPECT_EQ(e.length, f.length);
    EXPECT_EQ(e.max_speed, f.max_speed);
    EXPECT_TRUE(same_polygon(e.footprint, f.footprint));
    EXPECT_EQ(e.footprint_generated, f.footprint_generated);
    EXPECT_EQ(e.restrictions, f.restrictions);
    EXPECT_EQ(e.properties, f.properties);
    EXPECT_EQ(e.partition, f.partition);
  }
  EXPECT_EQ(a.conflict_sets(), b.conflict_sets());
  EXPECT_EQ(a.conflict_pair_count(), b.conflict_pair_count());
  for (EntityIndex v = 0; v < a.vertex_count(); ++v) {
    const auto moves_a = a.moves_from(v);
    const auto moves_b = b.moves_from(v);
    ASSERT_EQ(moves_a.size(), moves_b.size());
    for (std::size_t m = 0; m < moves_a.size(); ++m) {
      EXPECT_EQ(moves_a[m].edge, moves_b[m].edge);
      EXPECT_EQ(moves_a[m].to, moves_b[m].to);
    }
  }
}

TEST(JsonFormat, LoadsEveryFieldOfAGoodFile) {
  const auto loaded = load_topology_json(data_file("topology/small.json"));
  ASSERT_TRUE(loaded.has_value()) << dump(loaded.error());
  const Topology& t = *loaded;
  EXPECT_EQ(t.name(), "small");
  EXPECT_EQ(t.vertex_count(), 5u);
  EXPECT_EQ(t.edge_count(), 7u);
  EXPECT_TRUE(t.footprint_options().vertex_disc);
  EXPECT_EQ(t.footprint_options().disc_points, 8);
  EXPECT_DOUBLE_EQ(t.footprint_options().vertex_radius, 0.6);
  EXPECT_DOUBLE_EQ(t.footprint_options().edge_half_width, 0.4);

  const Vertex& home = t.vertex(*t.find("home"));
  EXPECT_EQ(home.kind, VertexKind::parking);
  EXPECT_EQ(home.orientation, 0.0);
  EXPECT_EQ(home.partition, "west");
  EXPECT_TRUE(home.footprint_generated);
  const Vertex& b = t.vertex(*t.find("b"));
  EXPECT_EQ(b.kind, VertexKind::station);
  EXPECT_EQ(b.restrictions.max_payload, 500.0);
  EXPECT_EQ(b.restrictions.allowed_vehicle_types, std::vector<std::string>{"agv"});
  EXPECT_EQ(b.properties.at("dock"), "north");
  const Vertex& c = t.vertex(*t.find("c"));
  EXPECT_EQ(c.kind, VertexKind::charger);
  EXPECT_FALSE(c.footprint_generated);
  EXPECT_DOUBLE_EQ(boost::geometry::area(c.footprint), 4.0);  // given counter-clockwise
  EXPECT_EQ(t.vertex(*t.find("a")).partition, "west");

  const Edge& home_a = t.edge(*t.find("home-a"));
  EXPECT_TRUE(home_a.bidirectional);
  EXPECT_DOUBLE_EQ(home_a.length, 4.0);  // from the positions
  const Edge& a_b = t.edge(*t.find("a-b"));
  EXPECT_FALSE(a_b.bidirectional);
  EXPECT_DOUBLE_EQ(a_b.length, 4.5);  // as given
  EXPECT_DOUBLE_EQ(a_b.max_speed, 2.0);
  EXPECT_EQ(a_b.restrictions.max_speed, 1.5);
  EXPECT_EQ(a_b.restrictions.forbidden_vehicle_types, std::vector<std::string>{"forklift"});
  EXPECT_EQ(a_b.restrictions.max_vehicle_length, 2.0);
  EXPECT_EQ(a_b.restrictions.max_vehicle_width, 1.2);
  EXPECT_EQ(a_b.properties.at("lane"), "main");
  EXPECT_EQ(t.partitions(), (std::vector<std::string>{"east", "west"}));

  // The diagonals a-c and d-b cross without sharing a vertex.
  const auto crossing = t.conflicts(*t.find("a-c"));
  EXPECT_NE(std::find(crossing.begin(), crossing.end(), *t.find("d-b")), crossing.end());
}

TEST(JsonFormat, RoundTripKeepsEverything) {
  const auto loaded = load_topology_json(data_file("topology/small.json"));
  ASSERT_TRUE(loaded.has_value()) << dump(loaded.error());
  const std::string written = write_topology_json(*loaded);
  const auto reloaded = parse_topology_json(written);
  ASSERT_TRUE(reloaded.has_value()) << dump(reloaded.error()) << written;
  expect_same_topology(*loaded, *reloaded);
  // Writing is deterministic: the reloaded topology writes the same text.
  EXPECT_EQ(write_topology_json(*reloaded), written);
}

TEST(JsonFormat, GeneratedFootprintsAreNotWritten) {
  const auto loaded = parse_topology_json(R"({"name": "plain",
      "vertices": [{"id": "a", "x": 0, "y": 0}, {"id": "b", "x": 3, "y": 0}],
      "edges": [{"id": "ab", "from": "a", "to": "b", "max_speed": 1}]})");
  ASSERT_TRUE(loaded.has_value()) << dump(loaded.error());
  const std::string written = write_topology_json(*loaded);
  EXPECT_EQ(written.find("\"footprint\""), std::string::npos) << written;
  EXPECT_NE(written.find("\"length\":3.0"), std::string::npos) << written;
  EXPECT_EQ(loaded->vertex(0).partition, "main");
}

TEST(JsonFormat, MovingAiImportRoundTripsThroughJson) {
  MovingAiOptions options;
  options.cell_size = 0.7;
  const auto imported = load_movingai_map(data_file("maps/small.map"), options);
  ASSERT_TRUE(imported.has_value()) << dump(imported.error());
  const auto reloaded = parse_topology_json(write_topology_json(*imported));
  ASSERT_TRUE(reloaded.has_value()) << dump(reloaded.error());
  expect_same_topology(*imported, *reloaded);
}

TEST(JsonFormat, UnreadableAndEmptyFilesAreReported) {
  const auto missing = errors_of(load_topology_json(data_file("topology/no-such-file.json")));
  ASSERT_EQ(missing.size(), 1u);
  EXPECT_EQ(missing[0].where, "");
  EXPECT_NE(missing[0].what.find("cannot open"), std::string::npos) << missing[0].what;

  const auto empty = errors_of(load_topology_json(data_file("topology/empty.json")));
  ASSERT_EQ(empty.size(), 1u);
  EXPECT_EQ(empty[0].what, "file is empty");

  const auto directory = errors_of(load_topology_json(data_file("topology")));
  ASSERT_EQ(directory.size(), 1u);
  EXPECT_EQ(directory[0].what, "is a directory");
}

TEST(JsonFormat, MalformedJsonNamesLineAndColumn) {
  const auto errors = errors_of(load_topology_json(data_file("topology/malformed.json")));
  ASSERT_EQ(errors.size(), 1u) << dump(errors);
  EXPECT_EQ(errors[0].where, "line 5, column 26");
  EXPECT_NE(errors[0].what.find("malformed JSON"), std::string::npos) << errors[0].what;
}

TEST(JsonFormat, WrongTypesMissingAndUnknownFieldsAreReportedWithTheirPath) {
  const auto errors = errors_of(load_topology_json(data_file("topology/wrong_types.json")));
  const std::string all = dump(errors);
  EXPECT_TRUE(has_diagnostic(errors, "vertices[1].kind", "unknown vertex kind 'dock'")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "vertices[2].x", "expected a number, got string")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "vertices[3].id", "expected a string, got number")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "vertices[3].colour", "unknown field")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "vertices[4]", "expected an object, got string")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "edges[0].max_speed", "expected a number, got string"))
      << all;
  EXPECT_TRUE(has_diagnostic(errors, "edges[0].bidirectional", "expected a boolean")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "edges[1].to", "required field is missing")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "edges[1].properties.lanes", "expected a string")) << all;
  EXPECT_EQ(errors.size(), 9u) << all;
}

TEST(JsonFormat, InvalidEntitiesAreReportedWithTheirPath) {
  const auto errors = errors_of(load_topology_json(data_file("topology/invalid_entities.json")));
  const std::string all = dump(errors);
  EXPECT_TRUE(has_diagnostic(errors, "vertices[2].id", "duplicate id 'a'")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "vertices[3].footprint", "intersects itself")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "edges[0].length", "positive")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "edges[1].max_speed", "positive")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "edges[2].to", "unknown vertex 'x'")) << all;
  EXPECT_EQ(errors.size(), 5u) << all;
}

TEST(JsonFormat, TopLevelAndOptionProblemsAreReported) {
  EXPECT_TRUE(has_diagnostic(errors_of(parse_topology_json("[1, 2]")), "(document)",
                             "expected an object, got array"));
  const auto missing = errors_of(parse_topology_json("{}"));
  EXPECT_TRUE(has_diagnostic(missing, "name", "required field is missing")) << dump(missing);
  EXPECT_TRUE(has_diagnostic(missing, "vertices", "required field is missing")) << dump(missing);
  EXPECT_TRUE(has_diagnostic(missing, "edges", "required field is missing")) << dump(missing);

  const auto options = errors_of(parse_topology_json(R"({"name": "o", "vertices": [],
      "edges": [], "footprint_options": {"vertex_shape": "hexagon", "disc_points": 2.5,
      "edge_halfwidth": 1}})"));
  EXPECT_TRUE(has_diagnostic(options, "footprint_options.vertex_shape", "unknown shape"))
      << dump(options);
  EXPECT_TRUE(has_diagnostic(options, "footprint_options.disc_points", "expected an integer"))
      << dump(options);
  EXPECT_TRUE(has_diagnostic(options, "footprint_options.edge_halfwidth", "unknown field"))
      << dump(options);

  const auto range = errors_of(parse_topology_json(R"({"name": "o", "vertices": [],
      "edges": [], "footprint_options": {"disc_points": 100000000000, "vertex_radius": -1}})"));
  EXPECT_TRUE(has_diagnostic(range, "footprint_options.disc_points", "between 3 and"))
      << dump(range);
  EXPECT_TRUE(has_diagnostic(range, "footprint_options.vertex_radius", "from 0.01 to 10000"))
      << dump(range);

  const auto huge = errors_of(parse_topology_json(R"({"name": "o", "vertices": [
      {"id": "a", "x": 1e999, "y": 0}], "edges": []})"));
  ASSERT_EQ(huge.size(), 1u);
  EXPECT_EQ(huge[0].where, "line 2, column 28") << "at the number's last character";
  EXPECT_EQ(huge[0].what, "malformed JSON: number overflow parsing '1e999'");
  // At the end of the text, the end counts as a character read, as nlohmann counts it.
  const auto cut = errors_of(parse_topology_json("{\"name\": \"t\",\n"));
  ASSERT_EQ(cut.size(), 1u);
  EXPECT_EQ(cut[0].where, "line 2, column 1");
  const auto cut_in_line = errors_of(parse_topology_json("{\"vertices\": ["));
  ASSERT_EQ(cut_in_line.size(), 1u);
  EXPECT_EQ(cut_in_line[0].where, "line 1, column 15");
}

TEST(JsonFormat, KeysGivenTwiceAreReportedWithTheirPath) {
  const auto errors = errors_of(parse_topology_json(R"({"name": "d", "vertices": [
      {"id": "a", "x": 0, "y": 0, "footprint": [[0, 0], [1, 0], [1, 1]]},
      {"id": "b", "x": 1, "y": 0, "x": 2, "properties": {"k": "1", "k": "2"}}],
      "edges": [], "name": "again"})"));
  const std::string all = dump(errors);
  EXPECT_TRUE(has_diagnostic(errors, "vertices[1].x", "key given twice")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "vertices[1].properties.k", "key given twice")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "name", "key given twice")) << all;
  EXPECT_EQ(errors.size(), 3u) << all;
}

// A duplicate at every level of a deeply nested object: the first hundred are named by
// their path, the rest counted (naming them all, each path as long as the nesting is deep,
// took minutes on a file of 120 KB).
TEST(JsonFormat, ManyKeysGivenTwiceAreNamedUpToAHundredThenCounted) {
  constexpr int kDepth = 3000;
  std::string nested;
  for (int level = 0; level < kDepth; ++level) nested += R"({"a": 1, "a": )";
  nested += "1" + std::string(kDepth, '}');
  const auto errors = errors_of(parse_topology_json(
      R"({"name": "n", "vertices": [], "edges": [], "properties": )" + nested + "}"));
  ASSERT_EQ(errors.size(), 101u);
  EXPECT_EQ(errors[0].where, "properties.a");
  EXPECT_EQ(errors[99].where.size(), std::string("properties").size() + 100 * 2);
  EXPECT_EQ(errors[100].what, std::to_string(kDepth - 100) + " more keys given twice");
}

// nlohmann's lexer takes a NUL byte for the end of the text: a file with one after a whole
// document loaded as if the rest were absent, and one cut short by NULs was reported as
// "unexpected end of input".
TEST(JsonFormat, NulByteIsRefusedWithLineAndColumn) {
  const std::string document = R"({"name": "z", "vertices": [], "edges": []})";
  ASSERT_TRUE(parse_topology_json(document).has_value()) << "the document alone is good";
  const auto trailing = errors_of(parse_topology_json(document + "\n" + '\0' + "garbage"));
  ASSERT_EQ(trailing.size(), 1u) << dump(trailing);
  EXPECT_EQ(trailing[0].where, "line 2, column 1");
  EXPECT_EQ(trailing[0].what, "malformed JSON: NUL byte (a JSON text cannot contain one)");
  const auto cut = errors_of(parse_topology_json("{\"name\": \"z\",\n  \"vertices\": [" +
                                                 std::string(4, '\0')));
  ASSERT_EQ(cut.size(), 1u) << dump(cut);
  EXPECT_EQ(cut[0].where, "line 2, column 16");
  EXPECT_EQ(cut[0].what, "malformed JSON: NUL byte (a JSON text cannot contain one)");
}

TEST(JsonFormat, FootprintPointsMustBePairsOfNumbers) {
  const auto errors = errors_of(parse_topology_json(R"({"name": "f", "vertices": [
      {"id": "a", "x": 0, "y": 0, "footprint": [[0, 0], [1], [1, "1"], 7]},
      {"id": "b", "x": 0, "y": 0, "footprint": {"x": 1}}], "edges": []})"));
  const std::string all = dump(errors);
  EXPECT_TRUE(has_diagnostic(errors, "vertices[0].footprint[1]", "an array of 1 elements"))
      << all;
  EXPECT_TRUE(has_diagnostic(errors, "vertices[0].footprint[2]", "[number, string]")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "vertices[0].footprint[3]", "got number")) << all;
  EXPECT_TRUE(has_diagnostic(errors, "vertices[1].footprint", "got object")) << all;
}

// The loader must turn any input into a topology or diagnostics, never crash or throw:
// random mutations of a valid file (byte changes, deletions, truncation).
TEST(JsonFormat, MutatedInputNeverCrashes) {
  const std::string_view valid = R"({"name": "m", "footprint_options": {"vertex_radius": 0.4},
    "vertices": [{"id": "a", "x": 0, "y": 0, "footprint": [[-1,-1],[1,-1],[1,1],[-1,1]]},
                 {"id": "b", "x": 3, "y": 0, "restrictions": {"max_speed": 1}}],
    "edges": [{"id": "ab", "from": "a", "to": "b", "max_speed": 1, "length": 3}]})";
  std::mt19937 random(7);
  const std::string alphabet = "{}[]\":,0123456789.-eE abxyz\\\n\x01\xff";
  std::uniform_int_distribution<std::size_t> pick_char(0, alphabet.size() - 1);
  std::size_t accepted = 0;
  for (int round = 0; round < 3000; ++round) {
    std::string text(valid);
    std::uniform_int_distribution<int> edits(1, 4);
    for (int edit = edits(random); edit > 0; --edit) {
      std::uniform_int_distribution<std::size_t> at(0, text.size() - 1);
      const std::size_t position = at(random);
      switch (random() % 3) {
        case 0: text[position] = alphabet[pick_char(random)]; break;
        case 1: text.erase(position, 1 + random() % 8); break;
        default: text.resize(position); break;
      }
      if (text.empty()) text = "x";
    }
    const auto result = parse_topology_json(text);
    if (result) {
      ++accepted;
    } else {
      EXPECT_FALSE(result.error().empty()) << "rejected without a reason: " << text;
    }
  }
  EXPECT_LT(accepted, 3000u);
}

}  // namespace
}  // namespace drover::topology
