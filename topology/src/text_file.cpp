#include "text_file.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <system_error>

namespace drover::topology::detail {

namespace {
Unexpected<Diagnostics> file_problem(std::string what) {
  return unexpected(Diagnostics{Diagnostic{"", std::move(what)}});
}
}  // namespace

Result<std::string, Diagnostics> read_text_file(const std::filesystem::path& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) return file_problem("is a directory");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return file_problem(std::string("cannot open: ") +
                        (errno != 0 ? std::strerror(errno) : "unknown error"));
  }
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) return file_problem("cannot read: I/O error");
  if (text.empty()) return file_problem("file is empty");
  return text;
}

}  // namespace drover::topology::detail
