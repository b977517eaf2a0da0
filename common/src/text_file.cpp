#include "drover/common/text_file.hpp"

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <system_error>

namespace drover {

Result<std::string> read_text_file(const std::filesystem::path& path) {
  const auto too_large = [] {
    return fail(ErrorCode::io, "larger than " + std::to_string(kMaxTextFileBytes >> 20) + " MiB");
  };
  std::error_code error;
  const auto type = std::filesystem::status(path, error).type();
  if (type == std::filesystem::file_type::directory) return fail(ErrorCode::io, "is a directory");
  // A device never ends (/dev/zero, /dev/urandom) or waits on a terminal; pipes stay
  // allowed, for process substitution.
  if (type == std::filesystem::file_type::character || type == std::filesystem::file_type::block ||
      type == std::filesystem::file_type::socket) {
    return fail(ErrorCode::io, "is a device or socket, not a file");
  }
  // A regular file too large is refused before reading it; a pipe, as it grows past the bound.
  if (type == std::filesystem::file_type::regular &&
      std::filesystem::file_size(path, error) > kMaxTextFileBytes && !error) {
    return too_large();
  }
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return fail(ErrorCode::io, std::string("cannot open: ") +
                                   (errno != 0 ? std::strerror(errno) : "unknown error"));
  }
  std::string text;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    if (text.size() + static_cast<std::size_t>(in.gcount()) > kMaxTextFileBytes) return too_large();
    text.append(chunk, static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) return fail(ErrorCode::io, "cannot read: I/O error");
  if (text.empty()) return fail(ErrorCode::io, "file is empty");
  return text;
}

std::string printable_excerpt(std::string_view text) {
  constexpr std::size_t kMaxShown = 40;
  std::string shown = "'";
  for (std::size_t i = 0; i < text.size() && i < kMaxShown; ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (std::isprint(byte)) {
      shown += text[i];
    } else {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02X", byte);
      shown += escaped;
    }
  }
  shown += text.size() > kMaxShown ? "...'" : "'";
  return shown;
}

}  // namespace drover
