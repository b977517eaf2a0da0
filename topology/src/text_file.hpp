#pragma once
// Reading a whole input file for the loaders, with the failures they report.

#include <filesystem>
#include <string>

#include "drover/common/result.hpp"
#include "drover/topology/topology_builder.hpp"

namespace drover::topology::detail {

/// The contents of `path`. Fails with one Diagnostic (empty `where`) when the file cannot
/// be opened or read, is a directory, or is empty.
Result<std::string, Diagnostics> read_text_file(const std::filesystem::path& path);

}  // namespace drover::topology::detail
