// `drover topology validate`: runs the built binary and checks exit codes and messages.

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

std::string env_or(const char* name, const char* fallback) {
  const char* value = std::getenv(name);
  return value != nullptr ? value : fallback;
}

fs::path source_dir() { return env_or("DROVER_SOURCE_DIR", "."); }
fs::path data_file(const std::string& name) { return source_dir() / "tests" / "data" / name; }

std::string shell_quote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

/// A scratch directory of this test process, removed at the end.
class ScratchDir {
 public:
  ScratchDir()
      : path_(fs::temp_directory_path() /
              ("drover-topology-cli-test-" + std::to_string(::getpid()))) {
    fs::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

struct CommandRun {
  int exit_code = -1;  ///< -1 when the process did not exit normally (a signal: a crash)
  std::string out;
  std::string err;
};

class TopologyValidate : public ::testing::Test {
 protected:
  /// Runs `drover topology validate ARGUMENTS...` and collects its output.
  CommandRun validate(const std::vector<std::string>& arguments) {
    const fs::path binary = fs::path(env_or("DROVER_BINARY_DIR", "build")) / "bin" / "drover";
    const fs::path out = scratch_.path() / "stdout";
    const fs::path err = scratch_.path() / "stderr";
    std::string command = shell_quote(binary.string()) + " topology validate";
    for (const auto& argument : arguments) command += " " + shell_quote(argument);
    command += " >" + shell_quote(out.string()) + " 2>" + shell_quote(err.string());
    const int status = std::system(command.c_str());
    CommandRun run;
    if (status != -1 && WIFEXITED(status)) run.exit_code = WEXITSTATUS(status);
    run.out = read_all(out);
    run.err = read_all(err);
    return run;
  }

  /// Every line of stderr is an `error: FILE...` line, and there is at least one.
  static void expect_error_lines(const CommandRun& run, const std::string& file) {
    const auto lines = lines_of(run.err);
    EXPECT_FALSE(lines.empty());
    for (const auto& line : lines) {
      EXPECT_EQ(line.rfind("error: " + file, 0), 0u) << line;
    }
  }

  static bool has_line(const std::string& text, const std::string& line) {
    const auto lines = lines_of(text);
    return std::find(lines.begin(), lines.end(), line) != lines.end();
  }

  ScratchDir scratch_;
};

TEST_F(TopologyValidate, GoodJsonPrintsOneLineSummary) {
  const std::string file = data_file("topology/small.json").string();
  const CommandRun run = validate({file});
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out, file + ": 5 vertices, 7 edges, 7 conflict pairs, partitions: east, west\n");
  EXPECT_EQ(run.err, "");
}

TEST_F(TopologyValidate, GoodMapWithCellSize) {
  const std::string file = data_file("maps/small.map").string();
  const CommandRun run = validate({file, "--cell-size", "0.5"});
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out, file + ": 17 vertices, 21 edges, 68 conflict pairs, partitions: main\n");
}

TEST_F(TopologyValidate, InvalidEntitiesGiveOneLinePerProblem) {
  const std::string file = data_file("topology/invalid_entities.json").string();
  const CommandRun run = validate({file});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out, "");
  expect_error_lines(run, file);
  EXPECT_EQ(lines_of(run.err).size(), 5u) << run.err;
  EXPECT_TRUE(has_line(run.err, "error: " + file +
                                    ":vertices[2].id: duplicate id 'a' (first used by vertices[0])"))
      << run.err;
  EXPECT_TRUE(has_line(run.err, "error: " + file + ":edges[2].to: unknown vertex 'x'"))
      << run.err;
  EXPECT_TRUE(has_line(run.err,
                       "error: " + file + ":edges[0].length: must be a positive finite number"))
      << run.err;
  EXPECT_TRUE(has_line(run.err, "error: " + file +
                                    ":edges[1].max_speed: must be a positive finite number"))
      << run.err;
  EXPECT_TRUE(has_line(run.err, "error: " + file +
                                    ":vertices[3].footprint: invalid polygon: it intersects itself"))
      << run.err;
}

TEST_F(TopologyValidate, WrongTypesAndMalformedJson) {
  const std::string types = data_file("topology/wrong_types.json").string();
  const CommandRun typed = validate({types});
  EXPECT_EQ(typed.exit_code, 2);
  expect_error_lines(typed, types);
  EXPECT_TRUE(has_line(typed.err,
                       "error: " + types + ":vertices[2].x: expected a number, got string"))
      << typed.err;

  const std::string malformed = data_file("topology/malformed.json").string();
  const CommandRun broken = validate({malformed});
  EXPECT_EQ(broken.exit_code, 2);
  expect_error_lines(broken, malformed);
  EXPECT_EQ(broken.err.rfind("error: " + malformed + ":line 5, column 26: malformed JSON", 0),
            0u)
      << broken.err;
}

TEST_F(TopologyValidate, UnreadableEmptyAndUnknownFiles) {
  const std::string empty = data_file("topology/empty.json").string();
  const CommandRun empty_run = validate({empty});
  EXPECT_EQ(empty_run.exit_code, 2);
  EXPECT_EQ(empty_run.err, "error: " + empty + ": file is empty\n");

  const std::string missing = (scratch_.path() / "missing.json").string();
  const CommandRun missing_run = validate({missing});
  EXPECT_EQ(missing_run.exit_code, 2);
  EXPECT_EQ(missing_run.err, "error: " + missing + ": cannot open: No such file or directory\n");

  const std::string text = (scratch_.path() / "plant.txt").string();
  std::ofstream(text) << "{}";
  const CommandRun text_run = validate({text});
  EXPECT_EQ(text_run.exit_code, 2);
  expect_error_lines(text_run, text);
  EXPECT_NE(text_run.err.find("unknown format"), std::string::npos) << text_run.err;
}

TEST_F(TopologyValidate, MalformedMapHeaderAndRows) {
  const std::string header = data_file("maps/bad_header.map").string();
  const CommandRun header_run = validate({header});
  EXPECT_EQ(header_run.exit_code, 2);
  expect_error_lines(header_run, header);
  EXPECT_TRUE(has_line(header_run.err,
                       "error: " + header + ":line 1: expected 'type octile', got 'type tile'"))
      << header_run.err;

  const std::string rows = data_file("maps/bad_rows.map").string();
  const CommandRun rows_run = validate({rows});
  EXPECT_EQ(rows_run.exit_code, 2);
  expect_error_lines(rows_run, rows);
  EXPECT_TRUE(has_line(rows_run.err,
                       "error: " + rows + ":line 8: expected 4 map rows, found 3"))
      << rows_run.err;
}

TEST_F(TopologyValidate, BadUsageExitsTwo) {
  const std::string json = data_file("topology/small.json").string();
  const CommandRun cell_on_json = validate({json, "--cell-size", "2"});
  EXPECT_EQ(cell_on_json.exit_code, 2);
  EXPECT_NE(cell_on_json.err.find("--cell-size applies to .map files only"), std::string::npos);

  const CommandRun negative = validate({data_file("maps/small.map").string(), "--cell-size", "-1"});
  EXPECT_EQ(negative.exit_code, 2);
  const CommandRun no_file = validate({});
  EXPECT_EQ(no_file.exit_code, 2);
}

TEST_F(TopologyValidate, BundledTopologiesAreValid) {
  for (const char* name : {"loop.json", "h_crossing.json", "warehouse.json"}) {
    const std::string file = (source_dir() / "launch" / "topologies" / name).string();
    const CommandRun run = validate({file});
    EXPECT_EQ(run.exit_code, 0) << file << "\n" << run.err;
    EXPECT_EQ(lines_of(run.out).size(), 1u) << run.out;
  }
  const CommandRun warehouse =
      validate({(source_dir() / "launch" / "topologies" / "warehouse.json").string()});
  EXPECT_NE(warehouse.out.find("partitions: east, west\n"), std::string::npos) << warehouse.out;
}

// The committed warehouse.json must be what its generator produces, so edits to the
// generator are never lost or half-applied.
TEST_F(TopologyValidate, WarehouseIsTheGeneratorsOutput) {
  if (std::system("python3 --version >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "python3 is not installed";
  }
  const fs::path directory = source_dir() / "launch" / "topologies";
  const fs::path generated = scratch_.path() / "warehouse.json";
  const std::string command = "python3 " +
                              shell_quote((directory / "generate_warehouse.py").string()) +
                              " --output " + shell_quote(generated.string());
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  EXPECT_EQ(read_all(generated), read_all(directory / "warehouse.json"))
      << "re-run launch/topologies/generate_warehouse.py and commit warehouse.json";
}

// Random bytes, with either extension: always exit 0 or 2 with messages, never a crash.
TEST_F(TopologyValidate, RandomBytesNeverCrash) {
  std::mt19937 random(99);
  const std::string map_alphabet = "typeoctilhgwdma 0123456789\n.@TGSW";
  for (int round = 0; round < 30; ++round) {
    const bool as_map = round % 2 == 1;
    const fs::path file = scratch_.path() / (as_map ? "fuzz.map" : "fuzz.json");
    std::string bytes(1 + random() % 400, '\0');
    for (auto& byte : bytes) {
      // Maps get mostly map-like characters so that the row checks are reached too.
      byte = as_map && random() % 4 != 0 ? map_alphabet[random() % map_alphabet.size()]
                                         : static_cast<char>(random() % 256);
    }
    if (as_map && round % 4 == 1) bytes = "type octile\nheight 2\nwidth 3\nmap\n" + bytes;
    std::ofstream(file, std::ios::binary) << bytes;
    const CommandRun run = validate({file.string()});
    ASSERT_TRUE(run.exit_code == 0 || run.exit_code == 2)
        << "exit " << run.exit_code << " on round " << round << "\n" << run.err;
    if (run.exit_code == 2) {
      expect_error_lines(run, file.string());
    }
  }
}

}  // namespace
