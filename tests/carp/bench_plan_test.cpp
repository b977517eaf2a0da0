// `drover bench plan`: runs the built binary on a small map and checks the JSON line, the
// paths file and the errors for bad input.

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string quoted(const std::string& text) {
  std::string q = "'";
  for (const char c : text) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

struct CommandRun {
  int exit_code = -1;  ///< -1: did not exit normally (a crash)
  std::string out;
  std::string err;
};

// Two rows joined at both ends around a wall: every agent has exactly two ways round.
constexpr const char* kMap =
    "type octile\nheight 3\nwidth 6\nmap\n"
    "......\n"
    ".@@@@.\n"
    "......\n";

class BenchPlan : public ::testing::Test {
 protected:
  BenchPlan()
      : dir_(fs::temp_directory_path() / ("drover-bench-plan-test-" + std::to_string(::getpid()))) {
    fs::create_directories(dir_);
    write("ring.map", kMap);
    write("ring.scen",
          "version 1\n"
          "0\tring.map\t6\t3\t0\t0\t5\t2\t7\n"
          "0\tring.map\t6\t3\t5\t0\t0\t2\t7\n"
          "0\tring.map\t6\t3\t2\t2\t3\t0\t7\n");
  }
  ~BenchPlan() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return (dir_ / name).string();
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  /// Runs `drover bench plan` with standard output to `out` (a file of the test's own by
  /// default, read back into the result).
  CommandRun bench_plan(const std::vector<std::string>& arguments,
                        const std::string& out_file = "") {
    return bench("plan", arguments, out_file);
  }

  /// Runs `drover bench WHICH ARGUMENTS...`, as bench_plan does.
  CommandRun bench(const std::string& which, const std::vector<std::string>& arguments,
                   const std::string& out_file = "") {
    const char* binary_dir = std::getenv("DROVER_BINARY_DIR");
    const fs::path binary = fs::path(binary_dir ? binary_dir : "build") / "bin" / "drover";
    std::string command = quoted(binary.string()) + " bench " + quoted(which);
    for (const auto& argument : arguments) command += " " + quoted(argument);
    const std::string out = out_file.empty() ? path("stdout") : out_file;
    command += " >" + quoted(out) + " 2>" + quoted(path("stderr"));
    const int status = std::system(command.c_str());
    CommandRun run;
    if (status != -1 && WIFEXITED(status)) run.exit_code = WEXITSTATUS(status);
    if (out == path("stdout")) run.out = read_all(out);
    run.err = read_all(path("stderr"));
    return run;
  }

  fs::path dir_;
};

TEST_F(BenchPlan, PrintsOneJsonLineAndWritesEveryAgentsSteps) {
  const CommandRun run = bench_plan({"--map", path("ring.map"), "--scen", path("ring.scen"), "--agents",
                              "3", "--paths", path("paths.jsonl")});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(run.out.find('\n'), run.out.size() - 1) << "exactly one line: " << run.out;
  const auto line = nlohmann::json::parse(run.out);
  EXPECT_EQ(line["map"], "ring.map");
  EXPECT_EQ(line["agents"], 3);
  EXPECT_EQ(line["astar_found"], 3);
  EXPECT_EQ(line["planned"].get<int>() + line["failed"].get<int>(), 3);
  EXPECT_GE(line["planned"].get<int>(), 1);
  EXPECT_GT(line["astar_seconds"].get<double>(), 0);
  EXPECT_DOUBLE_EQ(line["ratio_to_astar"].get<double>(),
                   line["plan_seconds"].get<double>() / line["astar_seconds"].get<double>());
  // The same over the planned agents alone: a part of each repeat's sums.
  EXPECT_GT(line["planned_astar_seconds"].get<double>(), 0);
  EXPECT_LE(line["planned_astar_seconds"].get<double>(), line["astar_seconds"].get<double>());
  EXPECT_LE(line["planned_plan_seconds"].get<double>(), line["plan_seconds"].get<double>());
  EXPECT_DOUBLE_EQ(line["planned_ratio_to_astar"].get<double>(),
                   line["planned_plan_seconds"].get<double>() /
                       line["planned_astar_seconds"].get<double>());

  // The paths: one line per agent, from its start at time 0 to its goal held for good.
  const std::vector<std::pair<std::string, std::string>> tasks{
      {"0,0", "5,2"}, {"5,0", "0,2"}, {"2,2", "3,0"}};
  std::istringstream paths(read_all(path("paths.jsonl")));
  double sum_of_costs = 0;
  double manhattan_sum = 0;  // a lower bound of the planned agents' free travel times
  int planned = 0;
  std::string text;
  for (int agent = 0; agent < 3; ++agent) {
    ASSERT_TRUE(std::getline(paths, text)) << "no line for agent " << agent;
    const auto entry = nlohmann::json::parse(text);
    EXPECT_EQ(entry["agent"], agent);
    const auto& steps = entry["steps"];
    if (steps.empty()) {
      EXPECT_FALSE(entry["error"].get<std::string>().empty());
      continue;
    }
    ++planned;
    EXPECT_EQ(steps.front()["entity"], tasks[agent].first);
    EXPECT_EQ(steps.front()["enter"], 0.0);
    EXPECT_EQ(steps.back()["entity"], tasks[agent].second);
    EXPECT_TRUE(steps.back()["leave"].is_null());
    for (std::size_t i = 1; i < steps.size(); ++i) {
      EXPECT_LE(steps[i]["enter"].get<double>(), steps[i - 1]["leave"].get<double>());
      EXPECT_GE(steps[i]["enter"].get<double>(), steps[i - 1]["enter"].get<double>());
    }
    sum_of_costs += steps.back()["enter"].get<double>();
    const auto cell = [](const std::string& id) {
      const auto comma = id.find(',');
      return std::pair{std::stoi(id.substr(0, comma)), std::stoi(id.substr(comma + 1))};
    };
    const auto [x0, y0] = cell(tasks[agent].first);
    const auto [x1, y1] = cell(tasks[agent].second);
    manhattan_sum += std::abs(x1 - x0) + std::abs(y1 - y0);  // 1 m cells at 1 m/s
  }
  EXPECT_FALSE(std::getline(paths, text)) << "one line per agent only";
  EXPECT_EQ(line["planned"], planned);
  EXPECT_DOUBLE_EQ(line["sum_of_costs"].get<double>(), sum_of_costs);
  // Reservation-free, the same agents arrive no later, and no sooner than their Manhattan
  // distance allows (the grid has no diagonal moves).
  EXPECT_LE(line["free_sum_of_costs"].get<double>(), sum_of_costs);
  EXPECT_GE(line["free_sum_of_costs"].get<double>(), manhattan_sum);
}

TEST_F(BenchPlan, RefusesBadInputWithExitCode2) {
  write("short.scen", "version 1\n0\tring.map\t6\t3\t0\t0\t5\n");
  write("wall.scen", "version 1\n0\tring.map\t6\t3\t1\t1\t5\t2\t7\n");
  // Made for a wider map: its cells would name other cells here.
  write("wide.scen", "version 1\n0\tring.map\t6\t3\t0\t0\t5\t2\t7\n"
                     "0\tring.map\t8\t3\t0\t0\t5\t2\t7\n");
  const struct {
    std::vector<std::string> arguments;
    std::string message;
  } cases[] = {
      {{"--map", path("ring.map"), "--scen", path("ring.scen"), "--agents", "4"},
       "but the scenario has only 3 tasks"},
      {{"--map", path("ring.map"), "--scen", path("short.scen"), "--agents", "1"},
       path("short.scen") + ":line 2: expected 9 fields"},
      {{"--map", path("ring.map"), "--scen", path("wall.scen"), "--agents", "1"},
       path("wall.scen") + ":line 2: start cell is not a passable cell"},
      {{"--map", path("ring.map"), "--scen", path("wide.scen"), "--agents", "2"},
       path("wide.scen") + ":line 3: the task is for a 8x3 map, but " + path("ring.map") +
           " is 6x3 (width x height)"},
      {{"--map", path("missing.map"), "--scen", path("ring.scen"), "--agents", "1"},
       path("missing.map")},
      {{"--map", path("ring.map"), "--scen", path("missing.scen"), "--agents", "1"},
       path("missing.scen")},
      {{"--map", path("ring.map"), "--scen", path("ring.scen"), "--agents", "0"},
       "--agents: must be from 1 to 1000000, got 0"},
      {{"--map", path("ring.map"), "--scen", path("ring.scen"), "--agents", "two"},
       "--agents: 'two' is not a number"},
      // Refused before the run: no result line for output that could not be written.
      {{"--map", path("ring.map"), "--scen", path("ring.scen"), "--agents", "1", "--paths",
        path("no-such-dir/paths.jsonl")},
       path("no-such-dir/paths.jsonl") + ": cannot open " + path("no-such-dir/paths.jsonl") +
           ".partial for writing"},
      // Never over an input.
      {{"--map", path("ring.map"), "--scen", path("ring.scen"), "--agents", "1", "--paths",
        path("ring.scen")},
       path("ring.scen") + ": it or " + path("ring.scen") + ".partial is an input of this run"},
      {{"--map", path("ring.map"), "--scen", path("ring.scen"), "--agents", "1", "--paths", ""},
       "--paths: must not be empty"},
      {{"--map", "", "--scen", path("ring.scen"), "--agents", "1"}, "--map: must not be empty"},
      {{"--map", path("ring.map"), "--scen", "", "--agents", "1"}, "--scen: must not be empty"},
      {{"--map", path("ring.map"), "--scen", path("ring.scen"), "--agents", "010"},
       "--agents 10 but the scenario has only 3 tasks"},  // ten, not octal eight
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.message);
    const CommandRun run = bench_plan(c.arguments);
    EXPECT_EQ(run.exit_code, 2);
    EXPECT_EQ(run.out, "");
    EXPECT_NE(run.err.find(c.message), std::string::npos) << run.err;
  }
  EXPECT_EQ(read_all(path("ring.scen")).rfind("version 1", 0), 0u) << "the input is intact";
}

// A complete run replaces an earlier run's paths file and leaves no partial one (the
// whole-or-nothing cases are output_file_test's).
TEST_F(BenchPlan, ThePathsFileIsReplacedWhenComplete) {
  write("paths.jsonl", "an earlier run's paths\n");
  const CommandRun run = bench_plan({"--map", path("ring.map"), "--scen", path("ring.scen"),
                                     "--agents", "3", "--paths", path("paths.jsonl")});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::istringstream lines(read_all(path("paths.jsonl")));
  std::string text;
  int count = 0;
  while (std::getline(lines, text)) ++count;
  EXPECT_EQ(count, 3);
  EXPECT_FALSE(std::filesystem::exists(path("paths.jsonl.partial")));
}

// A result that cannot be printed is a failed run (exit 1), not a silent success.
TEST_F(BenchPlan, AnUnwritableStandardOutputFailsTheRun) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  const CommandRun run = bench_plan(
      {"--map", path("ring.map"), "--scen", path("ring.scen"), "--agents", "1"}, "/dev/full");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("cannot write to standard output"), std::string::npos) << run.err;
}

// bench rpc --route checks its topology and route ends before it starts any process: bad
// input is exit 2 at once, not an agent's error and a failed route after seconds of waiting.
TEST_F(BenchPlan, BenchRpcRouteRefusesABadTopologyBeforeStartingAgents) {
  write("bad.json", "{\"name\": \"t\", \"vertices\": [{\"id\": \"a\", \"x\": 1e400, \"y\": 0}],\n"
                    "\"edges\": []}\n");
  write("one.json", "{\"name\": \"t\", \"vertices\": [{\"id\": \"a\", \"x\": 0, \"y\": 0}], "
                    "\"edges\": []}\n");
  const CommandRun bad = bench("rpc", {"--route", "--topology", path("bad.json"), "--calls", "1"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find(path("bad.json") + ":line 1, column 49: malformed JSON: number overflow"),
            std::string::npos)
      << bad.err;
  const CommandRun missing = bench(
      "rpc", {"--route", "--topology", path("one.json"), "--from", "a", "--to", "b", "--calls", "1"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find(path("one.json") + ": no vertex 'b'"), std::string::npos) << missing.err;
}

}  // namespace
