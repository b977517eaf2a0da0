#pragma once
// Starts the agents of a launch file as child processes, passes their output on with their
// agent id in front, restarts those that crash when their entry says so, and stops them
// all in order: on SIGINT / SIGTERM, or when the caller's tick says so.

#include <sys/types.h>

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "drover/common/result.hpp"
#include "drover/launcher/console.hpp"
#include "drover/launcher/launch_file.hpp"

namespace drover::launcher {

struct SupervisorOptions {
  /// The `drover` executable agents are started from.
  std::string executable;
  /// Options every agent gets after its own (domain id, clock).
  std::vector<std::string> common_options;
  /// How long an agent may take to end after SIGTERM before it gets SIGKILL.
  std::chrono::milliseconds stop_grace{5000};
  /// Real time between a crash and the restart.
  std::chrono::milliseconds restart_delay{1000};
  /// How often the tick is called.
  std::chrono::milliseconds tick_period{250};
  /// Called once when the stop is asked for, before any agent is stopped (the launcher
  /// takes its figures there: agents that are being stopped fail their work).
  std::function<void()> before_stop;
};

/// How one agent ended up.
struct AgentOutcome {
  std::string id;
  int restarts = 0;
  /// It ended on its own with a failure and was not restarted (no policy, or restarts used
  /// up). Ending on the launcher's SIGTERM is no failure.
  bool failed = false;
  /// Its last end, described ("exited with code 1", "killed by signal 9 (SIGKILL)").
  std::string last_end;
  /// Its last end on its own with a failure (a crash), described; empty: none.
  std::string last_failure;
};

struct SupervisorOutcome {
  /// What made it stop: "signal SIGINT", "signal SIGTERM" or the tick's reason.
  std::string stop_reason;
  std::vector<AgentOutcome> agents;

  bool any_failed() const;
};

class Supervisor {
 public:
  /// Called every tick period while the agents run; returns a reason to stop, or nullopt.
  using Tick = std::function<std::optional<std::string>()>;

  /// Blocks SIGINT, SIGTERM, SIGHUP, SIGQUIT and SIGCHLD in the calling thread, and so in
  /// every thread it creates afterwards, so that the supervisor receives them through a
  /// signalfd; ignores SIGPIPE. Call it first in main, before any thread exists.
  /// \return success, or io.
  static Status block_signals();

  Supervisor(std::vector<AgentEntry> agents, SupervisorOptions options, Console& console);
  ~Supervisor();
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;

  /// Starts every agent in order, supervises them until a signal or the tick asks to
  /// stop, then stops them in reverse kind order (load generators, logical agents,
  /// routing agents, simulated RANs, topology agents), each stage SIGTERM then SIGKILL
  /// after the grace period. A second SIGINT / SIGTERM while stopping kills the rest at
  /// once (SIGHUP and SIGQUIT stop it as SIGTERM does). Requires block_signals() first.
  /// \return how the agents ended, or io when the signalfd cannot be made (nothing started).
  Result<SupervisorOutcome> run(const Tick& tick);

 private:
  struct Agent;
  struct Stream;

  void start(std::size_t index);
  void read_stream(Stream& stream);
  void close_finished_streams();
  void reap_children();
  void on_exit(Agent& agent, int status);
  void start_due_restarts();
  /// Waits for output, signals and timers once, at most until `deadline`.
  /// \return the signal that arrived (SIGINT / SIGTERM), if any.
  std::optional<int> pump(std::chrono::steady_clock::time_point deadline);
  void stop_all(bool& kill_now);
  bool any_running(const std::vector<std::size_t>& indices) const;

  std::vector<Agent> agents_;
  std::vector<Stream> streams_;
  SupervisorOptions options_;
  Console& console_;
  int signal_fd_ = -1;
  bool stopping_ = false;
};

}  // namespace drover::launcher
