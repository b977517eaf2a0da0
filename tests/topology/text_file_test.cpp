// read_text_file, which every loader of a text format uses: what it refuses and why.

#include "drover/common/text_file.hpp"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <unistd.h>

namespace drover {
namespace {

namespace fs = std::filesystem;

class TextFile : public ::testing::Test {
 protected:
  fs::path dir_ = fs::temp_directory_path() / ("drover-text-file-test-" + std::to_string(::getpid()));
  void SetUp() override { fs::create_directories(dir_); }
  void TearDown() override { fs::remove_all(dir_); }
};

TEST_F(TextFile, ReadsAFileWhole) {
  const std::string bytes("one\r\ntwo\0three", 13);  // every byte kept, as given
  std::ofstream(dir_ / "a.txt", std::ios::binary) << bytes;
  const auto text = read_text_file(dir_ / "a.txt");
  ASSERT_TRUE(text.has_value()) << text.error().message;
  EXPECT_EQ(*text, bytes);
}

TEST_F(TextFile, ReadsAPipeUntilItsEnd) {
  int ends[2];
  ASSERT_EQ(::pipe(ends), 0);
  ASSERT_EQ(::write(ends[1], "piped", 5), 5);
  ::close(ends[1]);
  const auto text = read_text_file("/dev/fd/" + std::to_string(ends[0]));
  ::close(ends[0]);
  ASSERT_TRUE(text.has_value()) << text.error().message;
  EXPECT_EQ(*text, "piped");
}

TEST_F(TextFile, RefusesWhatIsNoFileOrHasNoText) {
  EXPECT_EQ(read_text_file(dir_).error().message, "is a directory");
  EXPECT_EQ(read_text_file(dir_ / "missing").error().message.rfind("cannot open: ", 0), 0u);
  std::ofstream(dir_ / "empty");
  EXPECT_EQ(read_text_file(dir_ / "empty").error().message, "file is empty");
  // A device never ends: refused before reading, not read until memory runs out.
  EXPECT_EQ(read_text_file("/dev/zero").error().message, "is a device or socket, not a file");
}

TEST_F(TextFile, RefusesAFileLargerThanTheBound) {
  const fs::path big = dir_ / "big";
  std::ofstream(big).close();
  fs::resize_file(big, kMaxTextFileBytes + 1);  // sparse: no disk space used
  const auto text = read_text_file(big);
  ASSERT_FALSE(text.has_value());
  EXPECT_EQ(text.error().message, "larger than 256 MiB");
  EXPECT_EQ(text.error().code, ErrorCode::io);
}

}  // namespace
}  // namespace drover
