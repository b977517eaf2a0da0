#pragma once
// The trace of a launch (`drover launch --trace FILE`): JSON lines, one per event, each with
// its shared-clock time, so that a run can be checked afterwards without Drover's code.
// The line format is documented in docs/launch.md.

#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"

namespace drover::launcher {

/// Thread-safe: readers of several topics write into one trace.
class TraceWriter {
 public:
  /// Creates (truncates) `path`. \return the writer, or invalid_argument when `path` is
  ///         one of `inputs` (the trace would wipe the launch's own files), or io naming
  ///         the file.
  static Result<std::unique_ptr<TraceWriter>> open(const std::filesystem::path& path,
                                                   const std::vector<std::filesystem::path>& inputs);
  ~TraceWriter();

  /// Writes one line: `line` with "t" (shared-clock ns) and "type" set first. A failed
  /// write is kept for flush() to report.
  void write(TimeNs time, const std::string& type, const nlohmann::json& fields);
  /// Flushes what was written to the file. \return success, or io naming the file and the
  ///         first write that failed (a full disk, say): the trace is incomplete.
  Status flush();
  std::uint64_t lines() const;

 private:
  TraceWriter(std::FILE* file, std::filesystem::path path) : file_(file), path_(std::move(path)) {}

  mutable std::mutex mutex_;
  std::FILE* file_;
  std::filesystem::path path_;
  std::uint64_t lines_ = 0;
  int write_error_ = 0;  ///< errno of the first failed write, 0 if none
};

}  // namespace drover::launcher
