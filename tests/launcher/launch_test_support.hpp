#pragma once
// Helpers of the launcher's process tests: launch files in a scratch directory, waiting
// for text in a child's output file (polled until a generous deadline, never a fixed
// sleep), the source tree.

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "tests/agents/child_process.hpp"

namespace drover::test {

inline std::filesystem::path source_dir() {
  const char* dir = std::getenv("DROVER_SOURCE_DIR");
  return dir != nullptr ? dir : DROVER_TEST_SOURCE_DIR;
}

/// A fresh directory for one test's files.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("drover_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

/// Polls `path` until `condition(content)` holds or `timeout` passes.
/// \return whether it held.
inline bool wait_for_output(const std::filesystem::path& path,
                            const std::function<bool(const std::string&)>& condition,
                            std::chrono::milliseconds timeout = std::chrono::seconds(60)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (condition(read_file(path.string()))) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return condition(read_file(path.string()));
}

/// How often `needle` occurs in `text`.
inline std::size_t count_of(const std::string& text, const std::string& needle) {
  std::size_t count = 0;
  for (auto at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++count;
  return count;
}

}  // namespace drover::test
