#pragma once
// Starting an agent as a child process that never outlives its parent; its stdout and
// stderr come back through pipes or go to given descriptors.

#include <sys/types.h>

#include <string>
#include <vector>

#include "drover/common/result.hpp"

namespace drover::launcher {

/// A started child: its pid and the read ends of its stdout and stderr pipes (non-blocking,
/// close-on-exec; the caller closes them once it has read them to the end).
struct SpawnedProcess {
  pid_t pid = -1;
  int stdout_fd = -1;
  int stderr_fd = -1;
};

/// Starts `executable` with `arguments` (argv[1..]) by fork and exec, its stdout and stderr
/// on `stdout_fd` and `stderr_fd` (-1: the caller's own). The child gets an empty signal
/// mask, its own process group (a Ctrl-C on the terminal reaches only the parent, which
/// stops its agents in order) and SIGTERM when the thread that started it ends (its parent
/// dies, or is killed), so no agent outlives it; it inherits no other descriptor than those
/// two and stdin. \return its pid, or io when fork fails. A failed exec shows as the child
/// writing the reason to its stderr and exiting with 127.
Result<pid_t> spawn_child(const std::string& executable, const std::vector<std::string>& arguments,
                          int stdout_fd, int stderr_fd);

/// spawn_child with the child's stdout and stderr going to new pipes.
/// \return the child and the pipes' read ends, or io when pipes or fork fail.
Result<SpawnedProcess> spawn_process(const std::string& executable,
                                     const std::vector<std::string>& arguments);

/// The path of the running executable (/proc/self/exe resolved), for starting agents with
/// the same `drover` binary. \return the path, or io.
Result<std::string> current_executable();

/// "exited with code N" or "killed by signal N (NAME)", for a waitpid() status.
std::string describe_wait_status(int status);

}  // namespace drover::launcher
