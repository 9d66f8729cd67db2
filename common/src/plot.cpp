#include "bbw/common/plot.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace bbw::plot {

namespace {

// Reads a path written by quote() ('...' with '' for a quote) at the start of `s`.
bool unquote(const std::string& s, std::string& out) {
  if (s.empty() || s[0] != '\'') return false;
  out.clear();
  for (std::size_t i = 1; i < s.size(); ++i) {
    if (s[i] == '\'') {
      if (i + 1 < s.size() && s[i + 1] == '\'') {
        out.push_back('\'');
        ++i;
        continue;
      }
      return true;
    }
    out.push_back(s[i]);
  }
  return false;
}

std::string last_line_of(const std::string& file) {
  std::ifstream f(file);
  std::string line, last;
  for (int n = 0; n < 10000 && std::getline(f, line); ++n) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  std::string shown;
  for (const char c : last.substr(0, 200)) shown.push_back(c >= 0x20 && c < 0x7f ? c : '?');
  return shown;
}

std::string describe(int status) {
  if (WIFEXITED(status)) {
    if (WEXITSTATUS(status) == 127) return "could not be started (is gnuplot installed? ./bbw setup)";
    return "exit " + std::to_string(WEXITSTATUS(status));
  }
  if (WIFSIGNALED(status)) return std::string("killed by signal ") + std::to_string(WTERMSIG(status));
  return "status " + std::to_string(status);
}

}  // namespace

std::string quote(const std::string& path) {
  std::string o = "'";
  for (const char c : path) {
    if (c == '\'') o += "''";
    else o += c;
  }
  return o + "'";
}

std::vector<std::string> outputs_of(const std::string& script) {
  std::vector<std::string> out;
  std::istringstream in(script);
  const std::string key = "set output ";
  for (std::string line; std::getline(in, line);) {
    const auto p = line.find_first_not_of(" \t");
    if (p == std::string::npos || line.compare(p, key.size(), key) != 0) continue;
    std::string path;
    if (unquote(line.substr(p + key.size()), path)) out.push_back(path);
  }
  return out;
}

void run_gnuplot(const std::string& script, const std::string& script_file) {
  {
    std::ofstream f(script_file);
    if (!f) throw std::runtime_error(script_file + ": cannot write gnuplot script");
    f << script;
    f.close();
    if (!f) throw std::runtime_error(script_file + ": cannot write gnuplot script");
  }
  const std::vector<std::string> outputs = outputs_of(script);
  // An older plot must not pass for this one, and a failed one leaves nothing behind.
  for (const auto& o : outputs) ::unlink(o.c_str());
  const std::string log = script_file + ".log";
  const int log_fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log_fd < 0) throw std::runtime_error(log + ": cannot write (" + std::strerror(errno) + ")");
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(log_fd);
    throw std::runtime_error("gnuplot for " + script_file + ": fork failed (" + std::strerror(errno) + ")");
  }
  if (pid == 0) {
    // gnuplot dies with this process: a killed tool leaves no plotter running.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(126);
    const int null_fd = ::open("/dev/null", O_RDWR);
    if (null_fd >= 0) {
      ::dup2(null_fd, STDIN_FILENO);
      ::dup2(null_fd, STDOUT_FILENO);
    }
    ::dup2(log_fd, STDERR_FILENO);
    ::execlp("gnuplot", "gnuplot", script_file.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(log_fd);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      status = -1;
      break;
    }
  }
  auto remove_outputs = [&] {
    std::string names;
    for (const auto& o : outputs) {
      ::unlink(o.c_str());
      names += (names.empty() ? "" : ", ") + o;
    }
    return names.empty() ? std::string("no plot") : names;
  };
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const std::string why = status == -1 ? std::string("could not be waited for") : describe(status);
    const std::string last = last_line_of(log);
    const std::string removed = remove_outputs();
    throw std::runtime_error("gnuplot " + why + " on " + script_file + (last.empty() ? "" : ": " + last) +
                             " (log " + log + "); not written: " + removed);
  }
  for (const auto& o : outputs) {
    struct stat st {};
    if (::stat(o.c_str(), &st) != 0 || st.st_size == 0) {
      const std::string last = last_line_of(log);
      const std::string removed = remove_outputs();
      throw std::runtime_error("gnuplot on " + script_file + " exited 0 but wrote no " + o +
                               (last.empty() ? "" : " (" + last + ")") + "; not written: " + removed);
    }
  }
}

}  // namespace bbw::plot
