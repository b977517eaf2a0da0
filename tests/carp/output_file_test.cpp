// bench/output_file: an output file appears whole or not at all, and never over an input.

#include "bench/output_file.hpp"

#include <fstream>
#include <future>
#include <iterator>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

namespace drover::bench {
namespace {

namespace fs = std::filesystem;

class OutputFileTest : public ::testing::Test {
 protected:
  OutputFileTest()
      : dir_(fs::temp_directory_path() / ("drover-output-file-test-" + std::to_string(::getpid()))) {
    fs::create_directories(dir_);
  }
  ~OutputFileTest() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  fs::path path(const std::string& name) const { return dir_ / name; }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
  }
  std::string read(const std::string& name) const {
    std::ifstream in(path(name));
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  fs::path dir_;
};

TEST_F(OutputFileTest, ACommittedFileReplacesTheOldOneAndLeavesNoPartial) {
  write("out.jsonl", "old\n");
  auto file = OutputFile::open(path("out.jsonl"), {});
  ASSERT_TRUE(file.has_value()) << file.error().message;
  file->stream() << "new\n";
  EXPECT_EQ(read("out.jsonl"), "old\n") << "replaced only on commit";
  ASSERT_TRUE(file->commit().has_value());
  EXPECT_EQ(read("out.jsonl"), "new\n");
  EXPECT_FALSE(fs::exists(path("out.jsonl.partial")));
}

TEST_F(OutputFileTest, AFileNeverCommittedLeavesTheOldOneAndRemovesItsPartial) {
  write("out.jsonl", "old\n");
  {
    auto file = OutputFile::open(path("out.jsonl"), {});
    ASSERT_TRUE(file.has_value()) << file.error().message;
    OutputFile moved = std::move(file).value();  // the one that removes the partial
    moved.stream() << "half a li";
    EXPECT_TRUE(fs::exists(path("out.jsonl.partial")));
  }
  EXPECT_EQ(read("out.jsonl"), "old\n");
  EXPECT_FALSE(fs::exists(path("out.jsonl.partial")));
}

TEST_F(OutputFileTest, NeverOverAnInputNorItsPartialName) {
  write("tasks.scen", "version 1\n");
  write("tasks.partial", "version 1\n");
  const auto over_input = OutputFile::open(path("tasks.scen"), {path("tasks.scen")});
  ASSERT_FALSE(over_input.has_value());
  EXPECT_NE(over_input.error().message.find("is an input"), std::string::npos);
  const auto over_partial = OutputFile::open(path("tasks"), {path("tasks.partial")});
  ASSERT_FALSE(over_partial.has_value());
  EXPECT_EQ(read("tasks.scen"), "version 1\n");
  EXPECT_EQ(read("tasks.partial"), "version 1\n");
}

TEST_F(OutputFileTest, WhatStandsAtThePartialNameIsNotRemovedWhenItCannotBeOpened) {
  fs::create_directories(path("out.jsonl.partial"));
  const auto file = OutputFile::open(path("out.jsonl"), {});
  ASSERT_FALSE(file.has_value());
  EXPECT_NE(file.error().message.find("for writing: Is a directory"), std::string::npos)
      << "says why: " << file.error().message;
  EXPECT_TRUE(fs::is_directory(path("out.jsonl.partial")));
}

TEST_F(OutputFileTest, ALinkAtThePartialNameIsReplacedNotWrittenThrough) {
  write("precious.txt", "keep me\n");
  fs::create_symlink(path("precious.txt"), path("out.jsonl.partial"));
  auto file = OutputFile::open(path("out.jsonl"), {});
  ASSERT_TRUE(file.has_value()) << file.error().message;
  file->stream() << "new\n";
  ASSERT_TRUE(file->commit().has_value());
  EXPECT_EQ(read("precious.txt"), "keep me\n");
  EXPECT_EQ(read("out.jsonl"), "new\n");
  EXPECT_FALSE(fs::is_symlink(path("out.jsonl")));
}

// `--paths /dev/null` or a pipe to another program: renaming the finished file over it
// would put a plain file in place of the device (as root, of the system's /dev/null).
TEST_F(OutputFileTest, APipeIsWrittenDirectlyNeverReplaced) {
  const fs::path pipe = path("pipe");
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  auto reader = std::async(std::launch::async, [&] {
    std::ifstream in(pipe);  // blocks until the writer opens the pipe
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  });
  {
    auto file = OutputFile::open(pipe, {});
    ASSERT_TRUE(file.has_value()) << file.error().message;
    file->stream() << "line 1\n";
    EXPECT_TRUE(file->commit().has_value());
  }
  EXPECT_EQ(reader.get(), "line 1\n");
  EXPECT_TRUE(fs::is_fifo(pipe)) << "the pipe was replaced";
  EXPECT_FALSE(fs::exists(path("pipe.partial")));
}

TEST_F(OutputFileTest, ADirectoryIsRefused) {
  fs::create_directories(path("out"));
  const auto file = OutputFile::open(path("out"), {});
  ASSERT_FALSE(file.has_value());
  EXPECT_NE(file.error().message.find("is a directory"), std::string::npos);
}

}  // namespace
}  // namespace drover::bench
