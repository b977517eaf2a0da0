#include "bench/output_file.hpp"

#include <cerrno>
#include <cstring>
#include <system_error>
#include <utility>

#include <fmt/format.h>

namespace drover::bench {

namespace {

bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code error;
  return std::filesystem::equivalent(a, b, error) && !error;
}

}  // namespace

OutputFile::OutputFile(std::filesystem::path path, std::filesystem::path partial)
    : path_(std::move(path)), partial_(std::move(partial)), out_(partial_) {}

OutputFile::OutputFile(OutputFile&& other) noexcept
    : path_(std::move(other.path_)),
      partial_(std::move(other.partial_)),
      out_(std::move(other.out_)),
      done_(std::exchange(other.done_, true)) {}  // only one of them may remove the file

Result<OutputFile> OutputFile::open(const std::filesystem::path& path,
                                    const std::vector<std::filesystem::path>& inputs) {
  std::filesystem::path partial = path;
  partial += ".partial";
  for (const auto& input : inputs) {
    if (same_file(path, input) || same_file(partial, input)) {
      return fail(ErrorCode::invalid_argument,
                  fmt::format("{}: it or {} is an input of this run; writing would overwrite it",
                              path.string(), partial.string()));
    }
  }
  std::error_code error;
  const auto kind = std::filesystem::status(path, error).type();
  if (kind == std::filesystem::file_type::directory) {
    return fail(ErrorCode::invalid_argument, fmt::format("{}: is a directory", path.string()));
  }
  // A device or a pipe is the reader's: renaming over it would put a plain file in its place.
  const bool special = kind != std::filesystem::file_type::not_found && kind != std::filesystem::file_type::none &&
                       kind != std::filesystem::file_type::regular;
  if (special) partial = path;
  // A link at the temporary name is replaced, not written through to the file it names.
  if (!special && std::filesystem::is_symlink(std::filesystem::symlink_status(partial, error)) &&
      !std::filesystem::remove(partial, error)) {
    return fail(ErrorCode::io, fmt::format("{}: cannot replace the link {}: {}", path.string(),
                                           partial.string(), error.message()));
  }
  errno = 0;
  OutputFile file(path, partial);
  if (!file.out_) {
    file.done_ = true;  // whatever stands at `partial` is not this run's to remove
    return fail(ErrorCode::io, fmt::format("{}: cannot open {} for writing: {}", path.string(),
                                           partial.string(),
                                           errno != 0 ? std::strerror(errno) : "unknown error"));
  }
  if (special) file.done_ = true;  // never removed: it is not ours
  return file;
}

OutputFile::~OutputFile() {
  if (done_) return;
  out_.close();
  std::error_code ignored;
  std::filesystem::remove(partial_, ignored);
}

Status OutputFile::commit() {
  out_.flush();
  const bool written = static_cast<bool>(out_);
  out_.close();
  std::error_code error;
  if (written && !out_.fail() && !direct()) std::filesystem::rename(partial_, path_, error);
  if (!written || out_.fail() || error) {
    if (!direct()) std::filesystem::remove(partial_, error);
    return fail(ErrorCode::io, fmt::format("{}: cannot write the file", path_.string()));
  }
  done_ = true;
  return {};
}

}  // namespace drover::bench
