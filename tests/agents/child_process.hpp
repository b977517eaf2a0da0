#pragma once
// A child process for multi-process tests: started by launcher::spawn_child (so it gets
// SIGTERM if the test dies, say killed by a CTest timeout, instead of running on in its
// domain), waited for through a pidfd (no sleeps), and always killed and reaped when the
// object goes away, even when an assertion failed half-way.

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace drover::test {

/// How a child ended.
struct ExitStatus {
  bool exited = false;  ///< ended by exit() / return from main
  int code = 0;         ///< exit code when exited, else the signal that killed it
};

class ChildProcess {
 public:
  /// Starts `path` with `args`, its stdout and stderr written to the given files when not
  /// empty (inherited otherwise). \return the child, or nullopt when it could not start
  /// (the reason is printed).
  static std::optional<ChildProcess> spawn(const std::string& path, const std::vector<std::string>& args,
                                           const std::string& stdout_file = {},
                                           const std::string& stderr_file = {});

  ChildProcess(ChildProcess&& other) noexcept;
  ChildProcess& operator=(ChildProcess&&) = delete;
  /// Kills (SIGKILL) and reaps the child if it is still there.
  ~ChildProcess();

  pid_t pid() const noexcept { return pid_; }
  /// Sends `signal_number` to the child (if not reaped yet).
  void signal(int signal_number) const;
  /// Waits until the child ends or `timeout` passes; reaps it. \return how it ended, or
  /// nullopt when it is still running.
  std::optional<ExitStatus> wait_exit(std::chrono::milliseconds timeout);

 private:
  ChildProcess(pid_t pid, int pidfd) : pid_(pid), pidfd_(pidfd) {}
  pid_t pid_ = -1;
  int pidfd_ = -1;
};

/// DROVER_BINARY_DIR/bin/<name>: where the build puts executables (ctest sets the variable;
/// without it, the directory of the running test executable, which is that same bin/).
std::string binary_path(const std::string& name);

/// The whole content of a file ("" when it cannot be read).
std::string read_file(const std::string& path);

}  // namespace drover::test
