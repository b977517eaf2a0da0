#include "drover/launcher/supervisor.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/signalfd.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <map>

#include "drover/launcher/process.hpp"

namespace drover::launcher {

using Clock = std::chrono::steady_clock;

struct Supervisor::Agent {
  AgentEntry entry;
  pid_t pid = -1;  ///< -1: not running
  int restarts = 0;
  bool failed = false;
  std::string last_end;
  std::string last_failure;
  std::optional<Clock::time_point> restart_at;
};

/// One pipe of one incarnation of an agent, read until its end.
struct Supervisor::Stream {
  int fd = -1;
  std::string agent_id;
  bool is_stderr = false;
  LineBuffer buffer;
  bool finished = false;
};

bool SupervisorOutcome::any_failed() const {
  return std::any_of(agents.begin(), agents.end(), [](const AgentOutcome& agent) { return agent.failed; });
}

namespace {

sigset_t supervised_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);   // the terminal or the ssh session went away
  sigaddset(&set, SIGQUIT);
  sigaddset(&set, SIGCHLD);
  return set;
}

bool failed_end(int status) { return !(WIFEXITED(status) && WEXITSTATUS(status) == 0); }

}  // namespace

Status Supervisor::block_signals() {
  const sigset_t set = supervised_signals();
  if (const int error = pthread_sigmask(SIG_BLOCK, &set, nullptr); error != 0) {
    return fail(ErrorCode::io, std::string("cannot block signals: ") + std::strerror(error));
  }
  // A reader of our output that ends (`| tee` on Ctrl-C) must not kill the launcher mid-way:
  // the agents are still to be stopped in order. Writes then fail instead (children get
  // the default back, spawn_child).
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  if (::sigaction(SIGPIPE, &ignore, nullptr) != 0) {
    return fail(ErrorCode::io, std::string("cannot ignore SIGPIPE: ") + std::strerror(errno));
  }
  return {};
}

Supervisor::Supervisor(std::vector<AgentEntry> agents, SupervisorOptions options, Console& console)
    : options_(std::move(options)), console_(console) {
  for (auto& entry : agents) {
    Agent agent;
    agent.entry = std::move(entry);
    agents_.push_back(std::move(agent));
  }
}

Supervisor::~Supervisor() {
  // run() ends with every agent stopped; this only guards an early exit.
  for (auto& agent : agents_) {
    if (agent.pid > 0) {
      ::kill(agent.pid, SIGKILL);
      ::waitpid(agent.pid, nullptr, 0);
    }
  }
  for (auto& stream : streams_) {
    if (stream.fd >= 0) ::close(stream.fd);
  }
  if (signal_fd_ >= 0) ::close(signal_fd_);
}

Result<SupervisorOutcome> Supervisor::run(const Tick& tick) {
  const sigset_t set = supervised_signals();
  signal_fd_ = ::signalfd(-1, &set, SFD_CLOEXEC | SFD_NONBLOCK);
  if (signal_fd_ < 0) return fail(ErrorCode::io, std::string("signalfd: ") + std::strerror(errno));

  SupervisorOutcome outcome;
  for (std::size_t index = 0; index < agents_.size(); ++index) start(index);

  auto next_tick = Clock::now() + options_.tick_period;
  while (outcome.stop_reason.empty()) {
    if (auto signal_number = pump(next_tick)) {
      outcome.stop_reason = std::string("signal SIG") + sigabbrev_np(*signal_number);
      break;
    }
    start_due_restarts();
    if (Clock::now() >= next_tick) {
      next_tick = Clock::now() + options_.tick_period;
      if (auto reason = tick()) outcome.stop_reason = *reason;
    }
  }
  if (options_.before_stop) options_.before_stop();
  console_.note("stopping (" + outcome.stop_reason + ")");
  bool kill_now = false;
  stop_all(kill_now);
  // Whatever the agents wrote last.
  while (std::any_of(streams_.begin(), streams_.end(), [](const Stream& s) { return !s.finished; })) {
    pump(Clock::now() + std::chrono::milliseconds(200));
  }
  close_finished_streams();
  for (const auto& agent : agents_) {
    outcome.agents.push_back({agent.entry.id, agent.restarts, agent.failed, agent.last_end, agent.last_failure});
  }
  return outcome;
}

void Supervisor::start(std::size_t index) {
  Agent& agent = agents_[index];
  agent.restart_at.reset();
  std::vector<std::string> arguments{std::string(subcommand(agent.entry.kind))};
  arguments.insert(arguments.end(), agent.entry.options.begin(), agent.entry.options.end());
  arguments.insert(arguments.end(), options_.common_options.begin(), options_.common_options.end());
  auto spawned = spawn_process(options_.executable, arguments);
  if (!spawned) {
    agent.failed = true;
    agent.last_end = agent.last_failure = "could not start: " + spawned.error().message;
    console_.note(agent.entry.id + " " + agent.last_end);
    return;
  }
  agent.pid = spawned->pid;
  for (const bool is_stderr : {false, true}) {
    Stream stream;
    stream.fd = is_stderr ? spawned->stderr_fd : spawned->stdout_fd;
    stream.agent_id = agent.entry.id;
    stream.is_stderr = is_stderr;
    streams_.push_back(std::move(stream));
  }
  console_.note("started " + agent.entry.id + " (" + std::string(kind_name(agent.entry.kind)) +
                ", pid " + std::to_string(agent.pid) + ")");
}

std::optional<int> Supervisor::pump(Clock::time_point deadline) {
  for (const auto& agent : agents_) {
    if (agent.restart_at && *agent.restart_at < deadline) deadline = *agent.restart_at;
  }
  std::vector<pollfd> fds{{signal_fd_, POLLIN, 0}};
  std::vector<std::size_t> stream_of;
  for (std::size_t index = 0; index < streams_.size(); ++index) {
    if (streams_[index].finished) continue;
    fds.push_back({streams_[index].fd, POLLIN, 0});
    stream_of.push_back(index);
  }
  const auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
  const int ready = ::poll(fds.data(), fds.size(), static_cast<int>(std::max<std::int64_t>(0, wait.count())));
  if (ready <= 0) return std::nullopt;  // timeout or EINTR: the caller's loop goes on
  for (std::size_t i = 1; i < fds.size(); ++i) {
    if (fds[i].revents != 0) read_stream(streams_[stream_of[i - 1]]);
  }
  close_finished_streams();
  std::optional<int> stop_signal;
  if (fds[0].revents & POLLIN) {
    signalfd_siginfo info{};
    while (::read(signal_fd_, &info, sizeof info) == static_cast<ssize_t>(sizeof info)) {
      if (info.ssi_signo == SIGCHLD) {
        reap_children();
      } else {
        stop_signal = static_cast<int>(info.ssi_signo);
      }
    }
  }
  return stop_signal;
}

void Supervisor::read_stream(Stream& stream) {
  std::array<char, 16384> chunk{};
  const auto emit = [&](std::string_view line) { console_.agent_line(stream.is_stderr, stream.agent_id, line); };
  for (;;) {
    const ssize_t count = ::read(stream.fd, chunk.data(), chunk.size());
    if (count > 0) {
      stream.buffer.append(std::string_view(chunk.data(), static_cast<std::size_t>(count)), emit);
      continue;
    }
    if (count < 0 && (errno == EAGAIN || errno == EINTR)) return;
    stream.buffer.finish(emit);  // end of file, or an error that ends the stream
    stream.finished = true;
    return;
  }
}

void Supervisor::close_finished_streams() {
  for (auto& stream : streams_) {
    if (stream.finished && stream.fd >= 0) {
      ::close(stream.fd);
      stream.fd = -1;
    }
  }
  std::erase_if(streams_, [](const Stream& stream) { return stream.finished; });
}

void Supervisor::reap_children() {
  for (;;) {
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, WNOHANG);
    if (pid <= 0) return;
    for (auto& agent : agents_) {
      if (agent.pid == pid) on_exit(agent, status);
    }
  }
}

void Supervisor::on_exit(Agent& agent, int status) {
  agent.pid = -1;
  agent.last_end = describe_wait_status(status);
  if (stopping_) return;  // asked to end: no failure, no restart
  if (!failed_end(status)) {
    console_.note(agent.entry.id + " " + agent.last_end);
    return;
  }
  agent.last_failure = agent.last_end;
  if (agent.entry.restart == RestartPolicy::on_failure && agent.restarts < agent.entry.max_restarts) {
    ++agent.restarts;
    agent.restart_at = Clock::now() + options_.restart_delay;
    console_.note(agent.entry.id + " " + agent.last_end + "; restarting (" +
                  std::to_string(agent.restarts) + "/" + std::to_string(agent.entry.max_restarts) + ")");
    return;
  }
  agent.failed = true;
  console_.note(agent.entry.id + " " + agent.last_end +
                (agent.entry.restart == RestartPolicy::on_failure ? "; no restarts left" : "; not restarted"));
}

void Supervisor::start_due_restarts() {
  const auto now = Clock::now();
  for (std::size_t index = 0; index < agents_.size(); ++index) {
    if (agents_[index].restart_at && *agents_[index].restart_at <= now) start(index);
  }
}

bool Supervisor::any_running(const std::vector<std::size_t>& indices) const {
  return std::any_of(indices.begin(), indices.end(), [&](std::size_t i) { return agents_[i].pid > 0; });
}

void Supervisor::stop_all(bool& kill_now) {
  stopping_ = true;
  std::map<AgentKind, std::vector<std::size_t>, std::greater<>> stages;
  for (std::size_t index = 0; index < agents_.size(); ++index) {
    agents_[index].restart_at.reset();
    stages[agents_[index].entry.kind].push_back(index);
  }
  for (const auto& [kind, indices] : stages) {
    for (auto index : indices) {
      if (agents_[index].pid > 0) ::kill(agents_[index].pid, kill_now ? SIGKILL : SIGTERM);
    }
    const auto grace_end = Clock::now() + options_.stop_grace;
    bool killed = kill_now;
    while (any_running(indices)) {
      const bool past_grace = Clock::now() >= grace_end;
      if ((past_grace || kill_now) && !killed) {
        for (auto index : indices) {
          if (agents_[index].pid <= 0) continue;
          console_.note(agents_[index].entry.id + " did not stop within the grace period: SIGKILL");
          ::kill(agents_[index].pid, SIGKILL);
        }
        killed = true;
      }
      const auto deadline = killed ? Clock::now() + std::chrono::milliseconds(200) : grace_end;
      if (pump(deadline)) kill_now = true;  // a second Ctrl-C: no more waiting
    }
  }
}

}  // namespace drover::launcher
