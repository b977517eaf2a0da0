#include "tests/agents/child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <utility>

#include "drover/launcher/process.hpp"

namespace drover::test {

std::optional<ChildProcess> ChildProcess::spawn(const std::string& path, const std::vector<std::string>& args,
                                                const std::string& stdout_file,
                                                const std::string& stderr_file) {
  const auto open_output = [](const std::string& file) {
    return file.empty() ? -1 : ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  };
  const int out = open_output(stdout_file);
  const int err = open_output(stderr_file);
  std::optional<pid_t> started;
  if ((out < 0 && !stdout_file.empty()) || (err < 0 && !stderr_file.empty())) {
    std::cerr << "cannot open the output files of " << path << ": " << std::strerror(errno) << "\n";
  } else if (auto spawned = launcher::spawn_child(path, args, out, err); !spawned) {
    std::cerr << spawned.error().message << "\n";
  } else {
    started = *spawned;
  }
  if (out >= 0) ::close(out);
  if (err >= 0) ::close(err);
  if (!started) return std::nullopt;
  const pid_t pid = *started;
  const int pidfd = static_cast<int>(::syscall(SYS_pidfd_open, pid, 0));
  if (pidfd < 0) {
    std::cerr << "pidfd_open failed: " << std::strerror(errno) << "\n";
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    return std::nullopt;
  }
  return ChildProcess(pid, pidfd);
}

ChildProcess::ChildProcess(ChildProcess&& other) noexcept
    : pid_(std::exchange(other.pid_, -1)), pidfd_(std::exchange(other.pidfd_, -1)) {}

ChildProcess::~ChildProcess() {
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
  if (pidfd_ >= 0) ::close(pidfd_);
}

void ChildProcess::signal(int signal_number) const {
  if (pid_ > 0) ::kill(pid_, signal_number);
}

std::optional<ExitStatus> ChildProcess::wait_exit(std::chrono::milliseconds timeout) {
  if (pid_ <= 0) return std::nullopt;
  pollfd fd{pidfd_, POLLIN, 0};
  int ready = 0;
  do {
    ready = ::poll(&fd, 1, static_cast<int>(timeout.count()));
  } while (ready < 0 && errno == EINTR);
  if (ready <= 0) return std::nullopt;
  int status = 0;
  if (::waitpid(pid_, &status, 0) != pid_) return std::nullopt;
  pid_ = -1;
  if (WIFEXITED(status)) return ExitStatus{true, WEXITSTATUS(status)};
  return ExitStatus{false, WIFSIGNALED(status) ? WTERMSIG(status) : 0};
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string binary_path(const std::string& name) {
  if (const char* dir = std::getenv("DROVER_BINARY_DIR"); dir != nullptr) {
    return std::string(dir) + "/bin/" + name;
  }
  // Run by hand, not by ctest: the executables are beside the test's own (build/bin).
  if (const auto self = launcher::current_executable(); self) {
    return (std::filesystem::path(*self).parent_path() / name).string();
  }
  return "./bin/" + name;
}

}  // namespace drover::test
