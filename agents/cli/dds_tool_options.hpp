#pragma once
// Options every DDS-talking command of droverctl shares, and the participant it talks
// through (named "droverctl-<pid>", so that several operators may run it at once).

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "drover/common/result.hpp"
#include "drover/dds/participant.hpp"

namespace drover::cli {

struct DdsToolOptions {
  std::uint32_t domain_id = 0;
  double timeout_seconds = 2.0;
  std::string xml_profile;

  std::chrono::milliseconds timeout() const {
    return std::chrono::milliseconds(static_cast<std::int64_t>(timeout_seconds * 1000.0));
  }
};

/// Adds --domain, --timeout (seconds, how long to wait for agents, default
/// `default_timeout_seconds`; not added when that is 0: a command that waits for no
/// answer) and --xml-profile.
void add_dds_tool_options(CLI::App& command, DdsToolOptions& options, double default_timeout_seconds);

/// The tool's participant. \return it, or the participant's error (invalid_argument for
/// a bad XML profile file).
Result<std::unique_ptr<dds::Participant>> open_tool_participant(const DdsToolOptions& options);

}  // namespace drover::cli
