// A child process with its output in log files, waited on through a pidfd (poll with a
// deadline, never a sleep). Used by bbw_launch, the system tests and the DDS benchmarks.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace bbw::runtime {

using Clock = std::chrono::steady_clock;

struct ExitStatus {
  bool exited = false;  // normal exit (code valid); otherwise killed by `signal`
  int code = 0;
  int signal = 0;
  bool ok() const { return exited && code == 0; }
  std::string describe() const;  // "exit 0", "exit 3", "killed by SIGKILL"
};

class Child {
 public:
  // Starts argv[0] (a path) with argv; stdout and stderr go to the given files (created or
  // truncated). `extra_env` entries ("KEY=VALUE") are added to this process's environment.
  // Throws std::runtime_error when the process cannot be started.
  Child(std::string name, const std::vector<std::string>& argv, const std::string& stdout_file,
        const std::string& stderr_file, const std::vector<std::string>& extra_env = {});
  ~Child();  // a still running child is killed (SIGKILL) and reaped
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  const std::string& name() const { return name_; }
  pid_t pid() const { return pid_; }
  int pidfd() const { return pidfd_; }
  // The exit status once reaped (by poll, wait_until or stop).
  const std::optional<ExitStatus>& status() const { return status_; }

  // Reaps the child if it has exited (non-blocking); nullopt while it runs.
  std::optional<ExitStatus> poll();
  // Waits until the child exits or the deadline passes.
  std::optional<ExitStatus> wait_until(Clock::time_point deadline);
  void send_signal(int sig);
  // True once when the child has stopped (SIGSTOP) since the last call; never blocks. A child
  // that freezes itself this way asks to be killed at that instant (scheduled process faults).
  bool take_stop();
  // SIGTERM, then SIGKILL if it has not exited after `grace`. Returns the exit status.
  ExitStatus stop(std::chrono::milliseconds grace);

 private:
  std::string name_;
  pid_t pid_ = -1;
  int pidfd_ = -1;
  std::optional<ExitStatus> status_;
};

// Waits until one of `children` that is still running exits, or the deadline passes.
// Returns its index, or -1 on timeout (or when none is running).
int wait_any(const std::vector<Child*>& children, Clock::time_point deadline);

// The directory holding the running executable (for sibling binaries such as bbw_corner).
std::string executable_dir();

}  // namespace bbw::runtime
