#pragma once
// Reading a whole input file, and quoting its bytes in an error message: what every loader
// of a text format (topologies, MovingAI maps and scenarios) needs alike.

#include <filesystem>
#include <string>
#include <string_view>

#include "drover/common/result.hpp"

namespace drover {

/// The most read_text_file reads: far more than any topology, map or scenario, yet a bound
/// for a file that never ends (a pipe fed forever).
inline constexpr std::size_t kMaxTextFileBytes = std::size_t{256} << 20;

/// The contents of `path` (a regular file or a pipe). Fails (ErrorCode::io) when the file
/// cannot be opened or read, is a directory, a device or a socket, is empty, or holds more
/// than kMaxTextFileBytes; the message says which, without the path (callers name it).
Result<std::string> read_text_file(const std::filesystem::path& path);

/// `text` quoted in single quotes, safe to print whatever bytes it holds: bytes that are not
/// printable ASCII shown as \xHH, and only the first 40 characters, then "...".
std::string printable_excerpt(std::string_view text);

}  // namespace drover
