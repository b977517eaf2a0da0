#pragma once
// One spdlog logger per agent, named after the agent id, so that every line a process
// writes says who wrote it (the launcher relies on this when it merges output).

#include <memory>
#include <string>

#include <spdlog/spdlog.h>

namespace drover {

/// Creates (or returns the existing) logger for an agent, writing to stderr, and makes it
/// spdlog's default. \param level one of trace, debug, info, warn, error, critical, off;
/// an unknown level falls back to info.
std::shared_ptr<spdlog::logger> make_agent_logger(const std::string& agent_id,
                                                  const std::string& level = "info");

}  // namespace drover
