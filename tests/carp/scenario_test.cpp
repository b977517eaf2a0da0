// MovingAI scenario parsing for `drover bench plan`: good files and the errors of bad ones.

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "bench/scenario.hpp"

namespace drover::bench {
namespace {

TEST(Scenario, ParsesTabSeparatedTasksInOrder) {
  const auto tasks = parse_scenario(
      "version 1\n"
      "3\tmaze.map\t32\t32\t5\t16\t31\t24\t31.31370850\n"
      "\n"
      "0\tmaze.map\t32\t32\t0\t0\t1\t0\t1\r\n",
      "s.scen");
  ASSERT_TRUE(tasks.has_value()) << tasks.error().message;
  ASSERT_EQ(tasks->size(), 2u);
  const ScenarioTask& first = (*tasks)[0];
  EXPECT_EQ(first.bucket, 3);
  EXPECT_EQ(first.map, "maze.map");
  EXPECT_EQ(first.map_width, 32);
  EXPECT_EQ(first.start_x, 5);
  EXPECT_EQ(first.start_y, 16);
  EXPECT_EQ(first.goal_x, 31);
  EXPECT_EQ(first.goal_y, 24);
  EXPECT_DOUBLE_EQ(first.optimal_length, 31.3137085);
  EXPECT_EQ(first.line, 2);
  EXPECT_EQ((*tasks)[1].line, 4);
}

TEST(Scenario, ReportsTheLineAndWhatIsWrong) {
  const struct {
    const char* text;
    const char* message;
  } cases[] = {
      {"", "s.scen:line 1: empty file"},
      {"\n  \r\n\t\n", "s.scen:line 3: only blank lines (expected \"version 1\")"},
      {"version 2\n", "s.scen:line 1: unsupported version '2'"},
      {"3\tm.map\t8\t8\t0\t0\t1\t1\t2\n", "s.scen:line 1: expected \"version 1\""},
      {"version 1\n0\tm.map\t8\t8\t0\t0\t1\t1\n", "s.scen:line 2: expected 9 fields"},
      {"version 1\n0\tm.map\t8\t8\tx\t0\t1\t1\t2\n", "s.scen:line 2: start x 'x' is not"},
      {"version 1\n0\tm.map\t8\t8\t-1\t0\t1\t1\t2\n", "s.scen:line 2: start x '-1' is not"},
      {"version 1\n0\tm.map\t8\t8\t0\t0\t8\t1\t2\n", "s.scen:line 2: start (0,0) or goal (8,1) lies"},
      {"version 1\n0\tm.map\t8\t8\t0\t0\t1\t1\tfar\n", "s.scen:line 2: optimal length 'far'"},
      {"version 1\n0\tm.map\t8\t8\t0\t0\t1\t1\tinf\n",
       "s.scen:line 2: optimal length 'inf' is not a finite number >= 0"},
      {"version 1\n0\tm.map\t8\t8\t0\t0\t99999999999\t1\t2\n",
       "s.scen:line 2: goal x '99999999999' is not a whole number from 0 to 2147483647"},
      // The file's bytes are quoted safely: escapes shown, not sent to the terminal.
      {"version 1\x1b[31mRED\n", "s.scen:line 1: expected \"version 1\", got 'version 1\\x1B[31mRED'"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.text);
    const auto tasks = parse_scenario(c.text, "s.scen");
    ASSERT_FALSE(tasks.has_value());
    EXPECT_EQ(tasks.error().code, ErrorCode::parse);
    EXPECT_EQ(tasks.error().message.rfind(c.message, 0), 0u) << tasks.error().message;
  }
}

TEST(Scenario, ALongLineIsQuotedInPart) {
  const auto tasks = parse_scenario("version " + std::string(1000, '9') + "x\n", "s.scen");
  ASSERT_FALSE(tasks.has_value());
  EXPECT_LT(tasks.error().message.size(), 120u) << tasks.error().message;
  EXPECT_NE(tasks.error().message.find("...'"), std::string::npos) << tasks.error().message;
}

TEST(Scenario, ADirectoryIsNotAScenario) {
  const auto tasks = load_scenario(std::filesystem::temp_directory_path());
  ASSERT_FALSE(tasks.has_value());
  EXPECT_EQ(tasks.error().code, ErrorCode::io);
  EXPECT_NE(tasks.error().message.find("is a directory"), std::string::npos)
      << tasks.error().message;
}

TEST(Scenario, AMissingFileIsAnIoError) {
  const auto tasks = load_scenario("/nonexistent/drover/s.scen");
  ASSERT_FALSE(tasks.has_value());
  EXPECT_EQ(tasks.error().code, ErrorCode::io);
  EXPECT_NE(tasks.error().message.find("/nonexistent/drover/s.scen"), std::string::npos);
}

}  // namespace
}  // namespace drover::bench
