// `droverctl alarms [--domain N] [--min-severity S] [--duration S] [--json]`: follows the
// operator alarms of a domain (drover/operator/alarm) as they are raised, one line each,
// until Ctrl-C, SIGTERM or the end of --duration. Each agent keeps its latest alarms
// (logical_agent::kAlarmsKept) for readers that match it later: those are shown first.

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "agents/cli/json_line.hpp"
#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "drover/common/clock.hpp"
#include "drover/dds/reader.hpp"
#include "drover/dds/shutdown_signal.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/logical_agent/names.hpp"
#include "drover/logical_agent/wire_names.hpp"

namespace drover::cli {
namespace {

struct AlarmsArguments {
  DdsToolOptions dds;
  std::string min_severity = "info";
  std::optional<double> duration_seconds;  ///< none: until a signal
  bool json = false;
};

/// `text` on one line: line breaks and other control characters as \n, \r, \t or \xHH
/// (an alarm's text may carry a RAN's reason: it must not forge a line of its own).
std::string one_line(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (byte < 0x20 || byte == 0x7f) {
      out += fmt::format("\\x{:02x}", byte);
    } else {
      out += c;
    }
  }
  return out;
}

/// One alarm as a line: "<shared-clock seconds> <SEVERITY> <vehicle or agent>: <text>", or
/// a JSON object (bytes that are not UTF-8 replaced, so that the line stays valid JSON).
std::string alarm_line(const msg::OperatorAlarm& alarm, bool json) {
  const std::string severity(logical_agent::severity_name(alarm.severity()));
  if (json) {
    return json_line({{"time_ns", alarm.time().ns()},
                      {"agent", alarm.agent()},
                      {"vehicle", alarm.vehicle()},
                      {"severity", severity},
                      {"text", alarm.text()}});
  }
  std::ostringstream line;
  line << std::fixed << std::setprecision(3) << ns_to_seconds(alarm.time().ns()) << " " << severity << " "
       << one_line(alarm.vehicle().empty() ? alarm.agent() : alarm.vehicle()) << ": " << one_line(alarm.text());
  return line.str();
}

int run_alarms(const AlarmsArguments& arguments) {
  const auto minimum = logical_agent::severity_from_name(arguments.min_severity);
  if (!minimum) {
    std::cerr << "error: --min-severity '" << arguments.min_severity
              << "': expected info, warning, error or critical\n";
    return kExitBadInput;
  }
  // A closed pipe (`droverctl alarms | head -1`) then fails the write, which ends the
  // command, instead of killing it.
  ::signal(SIGPIPE, SIG_IGN);
  if (auto installed = dds::install_shutdown_handlers(); !installed) {
    std::cerr << "error: " << installed.error().message << "\n";
    return kExitFailure;
  }
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  std::mutex output;  // alarms arrive on the reader's thread
  bool write_failed = false;
  dds::ReaderOptions kept_and_new;
  kept_and_new.qos = logical_agent::alarm_reader_qos();
  auto reader = dds::Reader<msg::OperatorAlarm>::create(
      **participant, logical_agent::kAlarmTopic,
      [&](const msg::OperatorAlarm& alarm) {
        if (alarm.severity() < *minimum) return;
        std::lock_guard lock(output);
        if (write_failed) return;
        // Flushed line by line: a follower piped into another tool sees each at once.
        std::cout << alarm_line(alarm, arguments.json) << std::endl;
        if (!std::cout) {  // a closed pipe, a full disk: nothing more can be shown
          write_failed = true;
          dds::request_shutdown();
        }
      },
      kept_and_new);
  if (!reader) {
    std::cerr << "error: " << reader.error().message << "\n";
    return kExitFailure;
  }
  std::cerr << "following alarms on domain " << arguments.dds.domain_id << " (Ctrl-C to stop)\n";
  if (arguments.duration_seconds) {
    // Whole milliseconds, at least one: --duration 0.0004 ends at once, not never.
    const auto end = std::chrono::steady_clock::now() +
                     std::chrono::milliseconds(std::max<std::int64_t>(
                         1, static_cast<std::int64_t>(*arguments.duration_seconds * 1000)));
    // In steps: one wait is bounded (about 24 days), the duration need not be.
    while (!dds::shutdown_requested() && std::chrono::steady_clock::now() < end) {
      dds::wait_for_shutdown(std::min<std::chrono::milliseconds>(
          std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now()),
          std::chrono::hours(24)));
    }
  } else {
    dds::wait_for_shutdown();
  }
  reader->reset();  // no callback after this
  // A failed write: run_app reports it ("cannot write to standard output") and exits 1.
  return write_failed ? kExitFailure : kExitOk;
}

}  // namespace

void add_alarms_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<AlarmsArguments>();
  auto* command = app.add_subcommand(
      "alarms",
      "Show the operator alarms the agents keep, then follow them as they are raised, one line each, until Ctrl-C or "
      "--duration");
  add_dds_tool_options(*command, arguments->dds, 0);
  command->add_option("--min-severity", arguments->min_severity,
                      "Show alarms of this severity and above: info, warning, error, critical (default info)");
  command->add_option("--duration", arguments->duration_seconds, "Stop after S seconds, S > 0 (default: at Ctrl-C)")
      ->transform(cli::positive());
  command->add_flag("--json", arguments->json, "One JSON object per alarm instead of text");
  command->callback([arguments, &context] { context.exit_code = run_alarms(*arguments); });
}

}  // namespace drover::cli
