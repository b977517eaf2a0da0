#pragma once
// Reading a whole input file, and quoting its bytes in an error message: what every loader
// of a text format (topologies, MovingAI maps and scenarios) needs alike.

#include <filesystem>
#include <string>
#include <string_view>

#include "drover/common/result.hpp"

namespace drover {

/// The contents of `path`. Fails (ErrorCode::io) when the file cannot be opened or read, is
/// a directory, or is empty; the message says which, without the path (callers name it).
Result<std::string> read_text_file(const std::filesystem::path& path);

/// `text` quoted in single quotes, safe to print whatever bytes it holds: bytes that are not
/// printable ASCII shown as \xHH, and only the first 40 characters, then "...".
std::string printable_excerpt(std::string_view text);

}  // namespace drover
