#include "drover/launcher/process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstring>
#include <filesystem>

namespace drover::launcher {

namespace {

void close_pair(int fds[2]) {
  if (fds[0] >= 0) ::close(fds[0]);
  if (fds[1] >= 0) ::close(fds[1]);
}

/// In the child between fork and exec: only async-signal-safe calls. `open_max` bounds the
/// descriptors closed one by one where close_range is missing (kernels before 5.9).
[[noreturn]] void exec_child(pid_t parent, const char* executable, char* const* argv, int out_fd,
                             int err_fd, int open_max) {
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, nullptr);
  struct sigaction by_default {};
  by_default.sa_handler = SIG_DFL;
  sigaction(SIGPIPE, &by_default, nullptr);  // the launcher ignores it; an ignored one is inherited
  setpgid(0, 0);
  prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (getppid() != parent) _exit(1);  // the parent died before prctl took effect
  if (out_fd >= 0) dup2(out_fd, STDOUT_FILENO);
  if (err_fd >= 0) dup2(err_fd, STDERR_FILENO);
  if (close_range(3, UINT_MAX, 0) != 0) {
    for (int fd = 3; fd < open_max; ++fd) close(fd);
  }
  execv(executable, argv);
  const char* reason = strerror(errno);
  const char prefix[] = "error: cannot execute ";
  (void)!write(STDERR_FILENO, prefix, sizeof prefix - 1);
  (void)!write(STDERR_FILENO, executable, strlen(executable));
  (void)!write(STDERR_FILENO, ": ", 2);
  (void)!write(STDERR_FILENO, reason, strlen(reason));
  (void)!write(STDERR_FILENO, "\n", 1);
  _exit(127);
}

}  // namespace

Result<pid_t> spawn_child(const std::string& executable, const std::vector<std::string>& arguments,
                          int stdout_fd, int stderr_fd) {
  // argv is built before fork: the child may not allocate.
  std::vector<std::string> storage;
  storage.reserve(arguments.size() + 1);
  storage.push_back(executable);
  storage.insert(storage.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (auto& argument : storage) argv.push_back(argument.data());
  argv.push_back(nullptr);

  const long open_max = ::sysconf(_SC_OPEN_MAX);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    return fail(ErrorCode::io,
                "cannot fork to start " + executable + ": " + std::strerror(errno));
  }
  if (pid == 0) {
    exec_child(parent, storage.front().c_str(), argv.data(), stdout_fd, stderr_fd,
               open_max > 0 && open_max < 1'000'000 ? static_cast<int>(open_max) : 65536);
  }
  return pid;
}

Result<SpawnedProcess> spawn_process(const std::string& executable,
                                     const std::vector<std::string>& arguments) {
  int out[2] = {-1, -1};
  int err[2] = {-1, -1};
  if (::pipe2(out, O_CLOEXEC) != 0 || ::pipe2(err, O_CLOEXEC) != 0) {
    const std::string reason = std::strerror(errno);
    close_pair(out);
    close_pair(err);
    return fail(ErrorCode::io, "cannot create pipes for " + executable + ": " + reason);
  }
  auto pid = spawn_child(executable, arguments, out[1], err[1]);
  ::close(out[1]);
  ::close(err[1]);
  if (!pid) {
    ::close(out[0]);
    ::close(err[0]);
    return unexpected(std::move(pid).error());
  }
  ::fcntl(out[0], F_SETFL, O_NONBLOCK);
  ::fcntl(err[0], F_SETFL, O_NONBLOCK);
  return SpawnedProcess{*pid, out[0], err[0]};
}

Result<std::string> current_executable() {
  std::error_code error;
  auto path = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return fail(ErrorCode::io, "cannot resolve /proc/self/exe: " + error.message());
  return path.string();
}

std::string describe_wait_status(int status) {
  if (WIFEXITED(status)) return "exited with code " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    const int signal_number = WTERMSIG(status);
    const char* name = sigabbrev_np(signal_number);
    return "killed by signal " + std::to_string(signal_number) +
           (name != nullptr ? std::string(" (SIG") + name + ")" : std::string());
  }
  return "ended (status " + std::to_string(status) + ")";
}

}  // namespace drover::launcher
