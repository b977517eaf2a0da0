// `drover launch FILE [--duration S] [--time-factor F] [--trace FILE] [--state-dir DIR]`:
// starts and supervises the agents of a launch file (docs/launch.md) until Ctrl-C, SIGTERM
// or the end of --duration, then prints a summary. Exit 0 after a clean run; 1 when an
// agent failed for good (not restarted) or the launcher could not run; 2 for a bad launch
// file or options (nothing is started then).

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "agents/cli/command.hpp"
#include "drover/common/clock.hpp"
#include "drover/common/logging.hpp"
#include "drover/dds/participant.hpp"
#include "drover/launcher/fleet_monitor.hpp"
#include "drover/launcher/launch_file.hpp"
#include "drover/launcher/process.hpp"
#include "drover/launcher/supervisor.hpp"
#include "drover/launcher/trace_writer.hpp"

namespace drover::cli {

namespace {

struct LaunchArguments {
  std::string launch_file;
  std::optional<double> duration_s;
  std::optional<double> time_factor;
  std::optional<std::uint32_t> domain_id;
  std::string trace_file;
  std::string state_dir;
  double stop_grace_s = 5;
  std::string log_level = "warn";
};

/// The directory relative journal paths live in: the one given (created by ensure_exists
/// when missing, so that a refused launch file leaves nothing behind), or a fresh temporary
/// one that is removed at the end.
class StateDirectory {
 public:
  static Result<StateDirectory> make(const std::string& given) {
    std::error_code error;
    if (!given.empty()) {
      auto path = std::filesystem::absolute(given, error);
      if (error) return fail(ErrorCode::io, "--state-dir " + given + ": " + error.message());
      return StateDirectory(std::move(path), false);
    }
    std::string pattern = (std::filesystem::temp_directory_path(error) / "drover-launch-XXXXXX").string();
    if (error || ::mkdtemp(pattern.data()) == nullptr) {
      return fail(ErrorCode::io, "cannot create a temporary state directory in " + pattern);
    }
    return StateDirectory(pattern, true);
  }
  StateDirectory(StateDirectory&& other) noexcept : path_(std::move(other.path_)), temporary_(other.temporary_) {
    other.temporary_ = false;
  }
  ~StateDirectory() {
    std::error_code ignored;
    if (temporary_) std::filesystem::remove_all(path_, ignored);
  }
  const std::filesystem::path& path() const noexcept { return path_; }
  /// Creates the directory if it is missing. \return io naming it when that fails.
  Status ensure_exists() const {
    std::error_code error;
    std::filesystem::create_directories(path_, error);
    if (error) return fail(ErrorCode::io, "--state-dir " + path_.string() + ": " + error.message());
    return {};
  }

 private:
  StateDirectory(std::filesystem::path path, bool temporary) : path_(std::move(path)), temporary_(temporary) {}
  std::filesystem::path path_;
  bool temporary_;
};

std::string lead_time_text(const launcher::OrderFigures& orders) {
  return orders.mean_lead_time_s ? fmt::format("{:.1f} s", *orders.mean_lead_time_s) : std::string("-");
}

std::string progress_line(const SharedClock& clock, const launcher::FleetFigures& figures) {
  return fmt::format("t = {:.1f} s | orders finished {}, failed {}, open {} | vehicles moving {}/{}",
                     ns_to_seconds(clock.now() - clock.epoch()), figures.orders.finished,
                     figures.orders.failed, figures.orders.open, figures.vehicles_moving,
                     figures.vehicles_reporting);
}

void print_summary(const launcher::LaunchFile& file, DurationNs ran_for,
                   const launcher::FleetFigures& figures, const launcher::SupervisorOutcome& outcome,
                   const launcher::TraceWriter* trace, const std::string& trace_file) {
  std::cout << fmt::format("summary of {} ({}): stopped on {} after {:.1f} s simulated\n",
                           file.name.empty() ? file.path.filename().string() : file.name, file.path.string(),
                           outcome.stop_reason, ns_to_seconds(ran_for));
  std::cout << fmt::format("  orders finished: {}\n  orders failed:   {}\n", figures.orders.finished,
                           figures.orders.failed);
  if (figures.orders.withdrawn > 0) std::cout << fmt::format("  orders withdrawn: {}\n", figures.orders.withdrawn);
  std::cout << fmt::format("  orders open:     {}\n", figures.orders.open);
  std::cout << fmt::format("  mean lead time:  {}\n", lead_time_text(figures.orders));
  std::cout << fmt::format("  vehicles:        {} reporting, {} RAN statuses, {} topology events\n",
                           figures.vehicles_reporting, figures.statuses, figures.topology_events);
  for (const auto& agent : outcome.agents) {
    if (agent.restarts == 0 && !agent.failed) continue;
    std::cout << fmt::format("  agent {}: {} restart(s){}; last failure: {}\n", agent.id, agent.restarts,
                             agent.failed ? ", FAILED" : "", agent.last_failure);
  }
  if (trace != nullptr) std::cout << fmt::format("  trace:           {} ({} lines)\n", trace_file, trace->lines());
  std::cout.flush();
}

int run(const LaunchArguments& arguments) {
  // First, before any thread exists: the supervisor takes its signals from a signalfd.
  if (auto blocked = launcher::Supervisor::block_signals(); !blocked) {
    std::cerr << "error: " << blocked.error().message << "\n";
    return kExitFailure;
  }
  make_agent_logger("launcher", arguments.log_level);
  auto state_dir = StateDirectory::make(arguments.state_dir);
  if (!state_dir) {
    std::cerr << "error: " << state_dir.error().message << "\n";
    return kExitBadInput;
  }
  auto file = launcher::load_launch_file(arguments.launch_file, state_dir->path());
  if (!file) {
    return report_bad_file(arguments.launch_file, file.error());
  }
  if (arguments.time_factor) file->time_factor = *arguments.time_factor;
  if (arguments.domain_id) file->domain_id = *arguments.domain_id;
  const TimeNs origin = SharedClock::unix_now();
  const TimeNs epoch = file->epoch_ns.value_or(origin);
  auto clock = SharedClock::create_at_origin(epoch, file->time_factor, origin);
  if (!clock) {
    // The epoch and time factor come from the file, or from --time-factor: name both.
    std::cerr << "error: " << file->path.string() << ": epoch " << epoch << " ns with time factor "
              << file->time_factor << " gives no usable shared clock: " << clock.error().message << "\n";
    return kExitBadInput;
  }
  auto executable = launcher::current_executable();
  if (!executable) {
    std::cerr << "error: " << executable.error().message << "\n";
    return kExitFailure;
  }
  // Only now that the launch file and the clock are good: a refused launch leaves no
  // directory behind. Before the trace, which may be written into it.
  if (auto exists = state_dir->ensure_exists(); !exists) {
    std::cerr << "error: " << exists.error().message << "\n";
    return kExitBadInput;
  }
  // Journal directories and profile files: none may fail at an agent's start after others
  // started.
  if (auto prepared = launcher::prepare_state(*file); !prepared) {
    std::cerr << "error: " << prepared.error().message << " (nothing started)\n";
    return kExitBadInput;
  }
  std::unique_ptr<launcher::TraceWriter> trace;
  if (!arguments.trace_file.empty()) {
    auto opened = launcher::TraceWriter::open(arguments.trace_file, {file->path, file->topology_file});
    if (!opened) {
      std::cerr << "error: " << opened.error().message << "\n";
      return kExitBadInput;
    }
    trace = std::move(*opened);
    trace->write(epoch, "launch",
                 {{"launch_file", file->path.string()},
                  {"topology", file->topology_file.string()},
                  {"domain", file->domain_id},
                  {"time_factor", file->time_factor},
                  {"epoch", epoch},
                  {"clock_origin_unix_ns", origin}});
  }
  dds::ParticipantOptions participant_options;
  participant_options.domain_id = file->domain_id;
  participant_options.agent_id = "launcher-" + std::to_string(::getpid());
  auto participant = dds::Participant::create(participant_options);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return kExitFailure;
  }
  auto monitor = launcher::FleetMonitor::create(**participant, trace.get());
  if (!monitor) {
    std::cerr << "error: " << monitor.error().message << "\n";
    return kExitFailure;
  }

  launcher::SupervisorOptions options;
  options.executable = *executable;
  options.stop_grace = std::chrono::milliseconds(static_cast<std::int64_t>(arguments.stop_grace_s * 1000));
  options.common_options = {"--domain",       std::to_string(file->domain_id),
                            "--time-factor",  fmt::format("{}", file->time_factor),
                            "--epoch",        std::to_string(epoch),
                            "--clock-origin", std::to_string(origin)};
  // The fleet's figures when the stop is asked for: agents being stopped end their orders
  // as failed ("shutting down"), which says nothing about the run.
  launcher::FleetFigures figures;
  TimeNs stopped_at = epoch;
  options.before_stop = [&] {
    figures = (*monitor)->figures();
    stopped_at = clock->now();
  };
  launcher::Console console;
  console.note(fmt::format("{}: {} agents on domain {}, time factor {}, state in {}", file->path.string(),
                           file->agents.size(), file->domain_id, file->time_factor,
                           state_dir->path().string()));
  const std::optional<TimeNs> end =
      arguments.duration_s ? std::optional<TimeNs>(epoch + seconds_to_ns(*arguments.duration_s)) : std::nullopt;
  launcher::Supervisor supervisor(file->agents, options, console);
  auto outcome = supervisor.run([&]() -> std::optional<std::string> {
    console.progress(progress_line(*clock, (*monitor)->figures()));
    if (end && clock->now() >= *end) return fmt::format("--duration {} s", *arguments.duration_s);
    return std::nullopt;
  });

  console.end_progress();
  if (!outcome) {
    std::cerr << "error: " << outcome.error().message << "\n";
    return kExitFailure;
  }
  const auto statuses = (*monitor)->figures();
  figures.statuses = statuses.statuses;
  figures.topology_events = statuses.topology_events;
  monitor->reset();
  participant->reset();
  const Status traced = trace ? trace->flush() : Status{};
  print_summary(*file, stopped_at - epoch, figures, *outcome, traced ? trace.get() : nullptr, arguments.trace_file);
  if (!traced) {
    std::cerr << "error: " << traced.error().message << "\n";
    return kExitFailure;
  }
  return outcome->any_failed() ? kExitFailure : kExitOk;
}

}  // namespace

void add_launch_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<LaunchArguments>();
  auto* command = app.add_subcommand(
      "launch", "Start and supervise the agents of a launch file (launch/*.json) until Ctrl-C, "
                "SIGTERM or the end of --duration, then print a summary");
  command->add_option("file", arguments->launch_file, "Launch file (docs/launch.md)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--duration", arguments->duration_s, "Stop after this many simulated seconds")
      ->transform(cli::positive());
  command->add_option("--time-factor", arguments->time_factor,
                      "Shared-clock seconds per real second, at most 1000 (overrides the launch file's)")
      ->transform(cli::positive_at_most(kMaxTimeFactor));
  command->add_option("--domain", arguments->domain_id, "DDS domain id (overrides the launch file's)")
      ->transform(cli::whole_in(0, 232));
  command->add_option("--trace", arguments->trace_file,
                      "Write every RAN status, topology event and order change as JSON lines");
  command->add_option("--state-dir", arguments->state_dir,
                      "Directory of relative journal paths (default: a temporary one, removed at the end)");
  command->add_option("--stop-grace", arguments->stop_grace_s,
                      "Real seconds an agent gets to end after SIGTERM before SIGKILL (default 5)")
      ->transform(cli::non_negative());
  command->add_option("--log-level", arguments->log_level, "The launcher's own log level (default warn)")
      ->check(cli::log_level());
  command->callback([arguments, &context] { context.exit_code = run(*arguments); });
}

}  // namespace drover::cli
