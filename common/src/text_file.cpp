#include "drover/common/text_file.hpp"

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <system_error>

namespace drover {

Result<std::string> read_text_file(const std::filesystem::path& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) return fail(ErrorCode::io, "is a directory");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return fail(ErrorCode::io, std::string("cannot open: ") +
                                   (errno != 0 ? std::strerror(errno) : "unknown error"));
  }
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
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
