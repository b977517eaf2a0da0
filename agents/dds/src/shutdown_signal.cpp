#include "drover/dds/shutdown_signal.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <limits>
#include <cerrno>
#include <cstring>
#include <string>

namespace drover::dds {
namespace {

// Self-pipe: the handler (async-signal-safe) writes one byte that is never read, so the
// read end stays readable and every waiter, now or later, sees the request through poll().
struct ShutdownPipe {
  int read_fd = -1;
  int write_fd = -1;
  int error = 0;

  ShutdownPipe() {
    int fds[2];
    if (pipe2(fds, O_CLOEXEC | O_NONBLOCK) != 0) {
      error = errno;
      return;
    }
    read_fd = fds[0];
    write_fd = fds[1];
  }
};

ShutdownPipe& shutdown_pipe() {
  static ShutdownPipe pipe;
  return pipe;
}

std::atomic<int> g_write_fd{-1};
std::atomic<bool> g_requested{false};

void notify() noexcept {
  if (g_requested.exchange(true)) return;
  const int fd = g_write_fd.load();
  if (fd >= 0) {
    const char byte = 1;
    [[maybe_unused]] const ssize_t written = ::write(fd, &byte, 1);
  }
}

extern "C" void on_shutdown_signal(int) { notify(); }

bool wait_ms(int timeout_ms) noexcept {
  if (g_requested.load()) return true;
  pollfd fd{shutdown_pipe().read_fd, POLLIN, 0};
  if (fd.fd < 0) return g_requested.load();
  for (;;) {
    const int ready = ::poll(&fd, 1, timeout_ms);
    if (ready >= 0 || errno != EINTR) break;
    if (g_requested.load()) return true;  // interrupted by the very signal
  }
  return g_requested.load();
}

}  // namespace

Status install_shutdown_handlers() {
  ShutdownPipe& pipe = shutdown_pipe();
  if (pipe.read_fd < 0) {
    return fail(ErrorCode::io, std::string("cannot create the shutdown pipe: ") + std::strerror(pipe.error));
  }
  g_write_fd.store(pipe.write_fd);
  struct sigaction action {};
  action.sa_handler = on_shutdown_signal;
  sigemptyset(&action.sa_mask);
  // SA_RESETHAND: a second signal takes the default action and ends a stuck process.
  action.sa_flags = SA_RESTART | SA_RESETHAND;
  for (int signal_number : {SIGINT, SIGTERM}) {
    if (sigaction(signal_number, &action, nullptr) != 0) {
      return fail(ErrorCode::io, std::string("cannot install the handler of signal ") +
                                     std::to_string(signal_number) + ": " + std::strerror(errno));
    }
  }
  return {};
}

void request_shutdown() noexcept {
  g_write_fd.store(shutdown_pipe().write_fd);
  notify();
}

bool shutdown_requested() noexcept { return g_requested.load(); }

void wait_for_shutdown() noexcept { wait_ms(-1); }

bool wait_for_shutdown(std::chrono::milliseconds timeout) noexcept {
  // poll() takes an int of milliseconds: a longer wait is cut to that (about 24 days), a
  // spurious "not requested" the caller's loop tells from a real timeout by the clock.
  const auto capped = std::clamp<std::int64_t>(timeout.count(), 0, std::numeric_limits<int>::max());
  return wait_ms(static_cast<int>(capped));
}

}  // namespace drover::dds
