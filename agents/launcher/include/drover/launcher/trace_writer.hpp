#pragma once
// The trace of a launch (`drover launch --trace FILE`): JSON lines, one per event, each with
// its shared-clock time, so that a run can be checked afterwards without Drover's code.
// The line format is documented in docs/launch.md.

#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>

#include <nlohmann/json.hpp>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"

namespace drover::launcher {

/// Thread-safe: readers of several topics write into one trace.
class TraceWriter {
 public:
  /// Creates (truncates) `path`. \return the writer, or io naming the file.
  static Result<std::unique_ptr<TraceWriter>> open(const std::filesystem::path& path);
  ~TraceWriter();

  /// Writes one line: `line` with "t" (shared-clock ns) and "type" set first.
  void write(TimeNs time, const std::string& type, const nlohmann::json& fields);
  /// Flushes what was written to the file.
  void flush();
  std::uint64_t lines() const;

 private:
  explicit TraceWriter(std::FILE* file) : file_(file) {}

  mutable std::mutex mutex_;
  std::FILE* file_;
  std::uint64_t lines_ = 0;
};

}  // namespace drover::launcher
