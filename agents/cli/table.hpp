#pragma once
// Plain-text tables for droverctl listings: columns padded to their widest cell.

#include <ostream>
#include <string>
#include <vector>

namespace drover::cli {

/// Prints `header` and `rows` (each as many cells as the header) to `out`, each column as
/// wide as its widest cell, two spaces apart, one line per row.
void print_table(std::ostream& out, const std::vector<std::string>& header,
                 const std::vector<std::vector<std::string>>& rows);

}  // namespace drover::cli
