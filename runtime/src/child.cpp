#include "bbw/runtime/child.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

extern char** environ;

namespace bbw::runtime {

namespace {

ExitStatus decode(int wstatus) {
  ExitStatus s;
  if (WIFEXITED(wstatus)) {
    s.exited = true;
    s.code = WEXITSTATUS(wstatus);
  } else if (WIFSIGNALED(wstatus)) {
    s.signal = WTERMSIG(wstatus);
  }
  return s;
}

int poll_timeout_ms(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
  if (left.count() <= 0) return 0;
  return static_cast<int>(std::min<long long>(left.count() + 1, 1 << 30));
}

}  // namespace

std::string ExitStatus::describe() const {
  if (exited) return "exit " + std::to_string(code);
  const char* name = sigabbrev_np(signal);
  return std::string("killed by SIG") + (name ? name : std::to_string(signal).c_str());
}

Child::Child(std::string name, const std::vector<std::string>& argv, const std::string& stdout_file,
             const std::string& stderr_file, const std::vector<std::string>& extra_env)
    : name_(std::move(name)) {
  if (argv.empty()) throw std::runtime_error(name_ + ": empty command line");
  if (::access(argv[0].c_str(), X_OK) != 0) {
    throw std::runtime_error(name_ + ": cannot start " + argv[0] + ": " + std::strerror(errno));
  }
  // Everything the child needs is prepared before fork(): after it, only async-signal-safe
  // calls (open, dup2, prctl, sigprocmask, execve) run in the child.
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::vector<std::string> env_store;
  for (char** e = environ; *e != nullptr; ++e) env_store.emplace_back(*e);
  for (const auto& e : extra_env) env_store.push_back(e);
  std::vector<char*> env;
  for (auto& e : env_store) env.push_back(e.data());
  env.push_back(nullptr);
  const int out_fd = ::open(stdout_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int err_fd = ::open(stderr_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int null_fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (out_fd < 0 || err_fd < 0 || null_fd < 0) {
    const int err = errno;
    for (int fd : {out_fd, err_fd, null_fd}) if (fd >= 0) ::close(fd);
    throw std::runtime_error(name_ + ": cannot open log files " + stdout_file + ", " + stderr_file +
                             ": " + std::strerror(err));
  }
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ == 0) {
    // Child: die with the parent (a crashed launcher or test leaves no orphans).
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(127);
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    for (int sig = 1; sig < NSIG; ++sig) ::sigaction(sig, &dfl, nullptr);
    sigset_t empty;
    sigemptyset(&empty);
    ::sigprocmask(SIG_SETMASK, &empty, nullptr);
    ::dup2(null_fd, STDIN_FILENO);
    ::dup2(out_fd, STDOUT_FILENO);
    ::dup2(err_fd, STDERR_FILENO);
    ::execve(args[0], args.data(), env.data());
    const char msg[] = "bbw: execve failed\n";
    [[maybe_unused]] auto ignored = ::write(STDERR_FILENO, msg, sizeof(msg) - 1);
    ::_exit(127);
  }
  const int fork_errno = errno;
  for (int fd : {out_fd, err_fd, null_fd}) ::close(fd);
  if (pid_ < 0) {
    throw std::runtime_error(name_ + ": cannot start " + argv[0] + ": " + std::strerror(fork_errno));
  }
  pidfd_ = static_cast<int>(syscall(SYS_pidfd_open, pid_, 0));
  if (pidfd_ < 0) {
    const int err = errno;
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    throw std::runtime_error(name_ + ": pidfd_open failed: " + std::strerror(err));
  }
}

Child::~Child() {
  if (!status_) {
    ::kill(pid_, SIGKILL);
    int ws = 0;
    ::waitpid(pid_, &ws, 0);
  }
  if (pidfd_ >= 0) ::close(pidfd_);
}

std::optional<ExitStatus> Child::poll() {
  if (status_) return status_;
  int ws = 0;
  const pid_t r = ::waitpid(pid_, &ws, WNOHANG);
  if (r == pid_) status_ = decode(ws);
  return status_;
}

std::optional<ExitStatus> Child::wait_until(Clock::time_point deadline) {
  for (;;) {
    if (auto s = poll()) return s;
    pollfd p{pidfd_, POLLIN, 0};
    const int n = ::poll(&p, 1, poll_timeout_ms(deadline));
    if (n == 0 && Clock::now() >= deadline) return poll();
    if (n < 0 && errno != EINTR) return poll();
  }
}

bool Child::take_stop() {
  if (status_) return false;
  siginfo_t si{};
  if (::waitid(P_PID, static_cast<id_t>(pid_), &si, WSTOPPED | WNOHANG) != 0) return false;
  return si.si_pid == pid_ && si.si_code == CLD_STOPPED;
}

void Child::send_signal(int sig) {
  if (!poll()) ::kill(pid_, sig);
}

ExitStatus Child::stop(std::chrono::milliseconds grace) {
  if (auto s = poll()) return *s;
  ::kill(pid_, SIGTERM);
  if (auto s = wait_until(Clock::now() + grace)) return *s;
  ::kill(pid_, SIGKILL);
  return *wait_until(Clock::time_point::max());
}

int wait_any(const std::vector<Child*>& children, Clock::time_point deadline) {
  for (;;) {
    std::vector<pollfd> fds;
    std::vector<int> index;
    for (std::size_t i = 0; i < children.size(); ++i) {
      if (children[i]->status()) continue;
      if (children[i]->poll()) return static_cast<int>(i);
      fds.push_back(pollfd{children[i]->pidfd(), POLLIN, 0});
      index.push_back(static_cast<int>(i));
    }
    if (fds.empty()) return -1;
    const int n = ::poll(fds.data(), fds.size(), poll_timeout_ms(deadline));
    if (n < 0 && errno != EINTR) return -1;
    for (std::size_t k = 0; k < fds.size(); ++k) {
      if (fds[k].revents != 0 && children[static_cast<std::size_t>(index[k])]->poll()) return index[k];
    }
    if (n == 0 && Clock::now() >= deadline) return -1;
  }
}

std::string executable_dir() {
  char buf[4096];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof(buf) - 1);
  if (n <= 0) return ".";
  std::string path(buf, static_cast<std::size_t>(n));
  const auto slash = path.rfind('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

}  // namespace bbw::runtime
