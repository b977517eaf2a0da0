#pragma once
// An output file that appears only when complete: written under a temporary name beside it
// and renamed over it at the end, so that a failed or interrupted run never leaves a cut-off
// file, nor wipes the one an earlier run wrote.

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "drover/common/result.hpp"

namespace drover::bench {

class OutputFile {
 public:
  /// Opens `path`'s temporary file (`path` + ".partial"), replacing any file of that name
  /// (a symbolic link there is replaced too, never written through).
  /// Fails, naming the file, when it cannot be created, when `path` is a directory, or when
  /// `path` or the temporary file is one of `inputs` (it would overwrite them). The file at
  /// `path` is replaced, not written through: a link there becomes a plain file. Except
  /// when `path` is no regular file (a device such as /dev/null, a pipe): that is written
  /// directly, never replaced.
  static Result<OutputFile> open(const std::filesystem::path& path,
                                 const std::vector<std::filesystem::path>& inputs);
  OutputFile(OutputFile&& other) noexcept;
  OutputFile& operator=(OutputFile&&) = delete;
  /// Removes the temporary file unless commit() succeeded.
  ~OutputFile();

  std::ofstream& stream() { return out_; }
  /// Flushes and renames the temporary file to the path. Fails, naming the file, when
  /// writing or renaming failed (the temporary file is removed then).
  Status commit();

 private:
  /// Writes to `partial`, renamed to `path` on commit; `partial` == `path`: directly.
  OutputFile(std::filesystem::path path, std::filesystem::path partial);
  bool direct() const { return partial_ == path_; }
  std::filesystem::path path_;
  std::filesystem::path partial_;
  std::ofstream out_;
  bool done_ = false;  // committed, or moved from: nothing to remove
};

}  // namespace drover::bench
