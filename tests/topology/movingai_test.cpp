// The MovingAI .map importer: cells, ids, positions, edges, footprints and bad maps.

#include "drover/topology/movingai.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include <unistd.h>

#include <gtest/gtest.h>

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

bool has_diagnostic(const Diagnostics& diagnostics, std::string_view where,
                    std::string_view what_part) {
  return std::any_of(diagnostics.begin(), diagnostics.end(), [&](const Diagnostic& d) {
    return d.where == where && d.what.find(what_part) != std::string::npos;
  });
}

class SmallMap : public ::testing::Test {
 protected:
  // small.map:        x: 01234
  //   row 0              ..@..
  //   row 1              .T...
  //   row 2              .....
  //   row 3              GW.S.
  void SetUp() override {
    MovingAiOptions options;
    options.cell_size = 2.0;
    options.max_speed = 1.5;
    auto loaded = load_movingai_map(data_file("maps/small.map"), options);
    ASSERT_TRUE(loaded.has_value()) << dump(loaded.error());
    topology_ = std::move(loaded).value();
  }

  EntityIndex at(std::string_view id) const {
    const auto found = topology_.find(id);
    EXPECT_TRUE(found.has_value()) << "no entity " << id;
    return found.value_or(kNoEntity);
  }

  bool in_conflict(std::string_view a, std::string_view b) const {
    const auto conflicts = topology_.conflicts(at(a));
    return std::find(conflicts.begin(), conflicts.end(), at(b)) != conflicts.end();
  }

  Topology topology_;
};

TEST_F(SmallMap, PassableCellsBecomeVerticesNamedByColumnAndRow) {
  EXPECT_EQ(topology_.name(), "small");
  EXPECT_EQ(topology_.vertex_count(), 17u);
  EXPECT_FALSE(topology_.find("2,0"));  // '@'
  EXPECT_FALSE(topology_.find("1,1"));  // 'T'
  EXPECT_FALSE(topology_.find("1,3"));  // 'W' is impassable
  EXPECT_TRUE(topology_.find("0,3"));   // 'G'
  EXPECT_TRUE(topology_.find("3,3"));   // 'S'
  // Position (x * cell, y * cell): the y axis follows the rows downwards.
  const Vertex& v = topology_.vertex(at("3,0"));
  EXPECT_DOUBLE_EQ(v.position.x(), 6.0);
  EXPECT_DOUBLE_EQ(v.position.y(), 0.0);
  EXPECT_DOUBLE_EQ(topology_.vertex(at("0,3")).position.y(), 6.0);
  EXPECT_DOUBLE_EQ(boost::geometry::area(v.footprint), 4.0);  // the cell square
  EXPECT_FALSE(v.footprint_generated);
  EXPECT_EQ(v.partition, "main");
}

TEST_F(SmallMap, FourNeighboursAreJoinedByBidirectionalEdges) {
  EXPECT_EQ(topology_.edge_count(), 21u);
  const Edge& right = topology_.edge(at("0,0-1,0"));
  EXPECT_TRUE(right.bidirectional);
  EXPECT_DOUBLE_EQ(right.length, 2.0);
  EXPECT_DOUBLE_EQ(right.max_speed, 1.5);
  EXPECT_EQ(right.from, at("0,0"));
  EXPECT_EQ(right.to, at("1,0"));
  EXPECT_TRUE(topology_.find("0,0-0,1"));
  EXPECT_FALSE(topology_.find("1,0-2,0"));  // into the '@'
  EXPECT_FALSE(topology_.find("1,0-0,0"));  // each pair once, named left-to-right

  const auto moves = topology_.moves_from(at("1,0"));
  ASSERT_EQ(moves.size(), 1u);  // back to 0,0 only: 2,0 is blocked and 1,1 is a tree
  EXPECT_EQ(moves[0].to, at("0,0"));
  EXPECT_EQ(moves[0].edge, at("0,0-1,0"));
}

TEST_F(SmallMap, FootprintsMakeTurnsConflictButNotStraightOrParallelMoves) {
  EXPECT_TRUE(in_conflict("0,2-1,2", "0,2"));      // an edge and its end vertices
  EXPECT_TRUE(in_conflict("0,2-1,2", "1,2"));
  EXPECT_FALSE(in_conflict("0,2-1,2", "2,2"));     // the next vertex only touches
  EXPECT_TRUE(in_conflict("2,2-3,2", "2,1-2,2"));  // perpendicular at a shared vertex
  EXPECT_TRUE(in_conflict("2,2-3,2", "2,2-2,3"));
  EXPECT_FALSE(in_conflict("0,2-1,2", "1,2-2,2"));  // straight on
  EXPECT_FALSE(in_conflict("2,1-3,1", "2,2-3,2"));  // parallel neighbours
  EXPECT_FALSE(in_conflict("2,2", "3,2"));          // neighbouring cells
  EXPECT_FALSE(in_conflict("2,1", "2,2-3,2"));
}

TEST(MovingAi, TheGridKeepsTheHeadersSizeWhereBorderCellsAreBlocked) {
  // A blocked last column and row leave no vertex there, yet scenarios name the header's size.
  const auto path = std::filesystem::temp_directory_path() /
                    ("drover-movingai-grid-" + std::to_string(::getpid()) + ".map");
  std::ofstream(path) << "type octile\nheight 3\nwidth 4\nmap\n...@\n...@\n@@@@\n";
  const auto loaded = load_movingai_grid(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(loaded.has_value()) << dump(loaded.error());
  EXPECT_EQ(loaded->width, 4);
  EXPECT_EQ(loaded->height, 3);
  EXPECT_EQ(loaded->topology.vertex_count(), 6u);
  EXPECT_EQ(loaded->topology.name(), path.stem().string());
}

TEST(MovingAi, AcceptsWindowsLineEndings) {
  const auto loaded = load_movingai_map(data_file("maps/crlf.map"));
  ASSERT_TRUE(loaded.has_value()) << dump(loaded.error());
  EXPECT_EQ(loaded->vertex_count(), 5u);
  EXPECT_EQ(loaded->edge_count(), 4u);
}

TEST(MovingAi, MalformedHeaderIsReportedPerLine) {
  const auto loaded = load_movingai_map(data_file("maps/bad_header.map"));
  ASSERT_FALSE(loaded.has_value());
  const auto& errors = loaded.error();
  EXPECT_TRUE(has_diagnostic(errors, "line 1", "expected 'type octile'")) << dump(errors);
  EXPECT_TRUE(has_diagnostic(errors, "line 2", "whole number")) << dump(errors);
  EXPECT_TRUE(has_diagnostic(errors, "line 4", "expected 'map'")) << dump(errors);
}

TEST(MovingAi, WrongRowsAndCharactersAreReportedPerLine) {
  const auto loaded = load_movingai_map(data_file("maps/bad_rows.map"));
  ASSERT_FALSE(loaded.has_value());
  const auto& errors = loaded.error();
  EXPECT_TRUE(has_diagnostic(errors, "line 6", "expected 5 cells, found 3")) << dump(errors);
  EXPECT_TRUE(has_diagnostic(errors, "line 7", "unexpected character 'x' at column 3"))
      << dump(errors);
  EXPECT_TRUE(has_diagnostic(errors, "line 8", "expected 4 map rows, found 3")) << dump(errors);
  EXPECT_EQ(errors.size(), 3u) << dump(errors);
}

TEST(MovingAi, ShortFilesAndBadOptionsAreReported) {
  const auto short_file = parse_movingai_map("type octile\nheight 3\n", "short");
  ASSERT_FALSE(short_file.has_value());
  EXPECT_TRUE(has_diagnostic(short_file.error(), "line 3", "the file ends in the header"))
      << dump(short_file.error());

  const auto too_many = parse_movingai_map("type octile\nheight 1\nwidth 2\nmap\n..\n..\n", "x");
  ASSERT_FALSE(too_many.has_value());
  EXPECT_TRUE(has_diagnostic(too_many.error(), "line 6", "expected 1 map rows, found 2"))
      << dump(too_many.error());

  const auto binary = parse_movingai_map("type octile\nheight 1\nwidth 2\nmap\n.\x01\n", "x");
  ASSERT_FALSE(binary.has_value());
  EXPECT_TRUE(has_diagnostic(binary.error(), "line 5", "'\\x01'")) << dump(binary.error());

  MovingAiOptions options;
  options.cell_size = 0;
  options.max_speed = -1;
  const auto bad_options = parse_movingai_map("type octile\nheight 1\nwidth 1\nmap\n.\n", "x",
                                              options);
  ASSERT_FALSE(bad_options.has_value());
  EXPECT_TRUE(has_diagnostic(bad_options.error(), "options.cell_size", "at least 0.01"));
  EXPECT_TRUE(has_diagnostic(bad_options.error(), "options.max_speed", "positive"));

  // The 1 002nd cell's centre, at 1 km a cell, lies past the coordinates a topology allows;
  // the size the error suggests fits.
  const std::string wide_map =
      "type octile\nheight 1\nwidth 1002\nmap\n" + std::string(1002, '.') + "\n";
  MovingAiOptions wide;
  wide.cell_size = 1000;
  const auto too_wide = parse_movingai_map(wide_map, "x", wide);
  ASSERT_FALSE(too_wide.has_value());
  EXPECT_TRUE(has_diagnostic(too_wide.error(), "options.cell_size", "at most 999.000"))
      << dump(too_wide.error());
  wide.cell_size = 999.0;
  const auto fits = parse_movingai_map(wide_map, "x", wide);
  EXPECT_TRUE(fits.has_value()) << dump(fits.error());
}

TEST(MovingAi, MutatedInputNeverCrashes) {
  const std::string valid = "type octile\nheight 3\nwidth 4\nmap\n.@..\n..T.\nG..S\n";
  const std::string alphabet = ".@TGSWx0123456789 \n\r\xff";
  std::mt19937 random(11);
  std::uniform_int_distribution<std::size_t> pick_char(0, alphabet.size() - 1);
  for (int round = 0; round < 3000; ++round) {
    std::string text = valid;
    for (int edit = 1 + static_cast<int>(random() % 3); edit > 0 && !text.empty(); --edit) {
      const std::size_t position = random() % text.size();
      if (random() % 2 == 0) {
        text[position] = alphabet[pick_char(random)];
      } else {
        text.erase(position, 1 + random() % 5);
      }
    }
    const auto result = parse_movingai_map(text, "fuzz");
    if (!result) {
      EXPECT_FALSE(result.error().empty()) << "rejected without a reason: " << text;
    }
  }
}

}  // namespace
}  // namespace drover::topology
