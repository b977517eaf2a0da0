#pragma once
// Checks of textual command-line options. An empty value must not slip through as "not
// given": `--partition ""` would serve the whole topology, `--db ""` run without a journal,
// and a vehicle "" address whichever logical agent answers first.
// Add them with Option::check.

#include <string_view>

#include <CLI/CLI.hpp>

namespace drover::cli {

/// An id that travels as a DDS key (vehicle, order, partition, agent): 1 to 255 bytes
/// without control characters (drover/common/identifier.hpp).
CLI::Validator identifier();
/// Any text but the empty one (an empty file name would be reported as a file named "",
/// which no message makes clear).
CLI::Validator non_empty();

/// Whether `level` is a log level every agent takes: trace, debug, info, warn, error, off
/// (spdlog would read any other text as off, silently).
bool is_log_level(std::string_view level);
/// --log-level of every agent: is_log_level.
CLI::Validator log_level();

}  // namespace drover::cli
