// Helpers shared by the system tests: paths into the trees this test was built from, a scratch
// folder per test, and running a process to completion with a deadline.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "bbw/runtime/child.hpp"

namespace bbw::system_test {

inline std::string src(const std::string& rel) { return std::string(BBW_TEST_SOURCE_DIR) + "/" + rel; }
inline std::string bin(const std::string& name) { return std::string(BBW_TEST_BINARY_DIR) + "/bin/" + name; }

inline std::string slurp(const std::string& file) {
  std::ifstream f(file);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// A test's scratch folders are removed when it passes and kept when it fails (for the post-mortem;
// a failure message names the folder). Without this every run left 10 MB per system test in /tmp.
class RemoveScratchOnPass : public ::testing::EmptyTestEventListener {
 public:
  static void add(const std::string& dir) {
    static RemoveScratchOnPass* listener = [] {
      auto* l = new RemoveScratchOnPass;
      ::testing::UnitTest::GetInstance()->listeners().Append(l);  // owned by gtest from here
      return l;
    }();
    listener->dirs_.push_back(dir);
  }
  void OnTestEnd(const ::testing::TestInfo& info) override {
    // BBW_KEEP_SCRATCH=1 keeps them also when the test passes (to compare a good run with a bad one).
    const char* keep = std::getenv("BBW_KEEP_SCRATCH");
    if (info.result() != nullptr && info.result()->Passed() && (keep == nullptr || std::string(keep) != "1")) {
      for (const auto& d : dirs_) {
        std::error_code ec;
        std::filesystem::remove_all(d, ec);
      }
    }
    dirs_.clear();
  }

 private:
  std::vector<std::string> dirs_;
};

// Whether a run can be started under SCHED_FIFO (root and chrt).
inline bool realtime_priority_available() { return ::geteuid() == 0 && ::access("/usr/bin/chrt", X_OK) == 0; }
// argv under SCHED_FIFO 10 (`/usr/bin/chrt -f 10` before it, inherited by every process and thread
// it starts) when realtime_priority_available(); else argv as it is.
inline std::vector<std::string> at_realtime_priority(std::vector<std::string> argv) {
  if (realtime_priority_available()) argv.insert(argv.begin(), {"/usr/bin/chrt", "-f", "10"});
  return argv;
}

// A fresh, empty folder /tmp/bbw_<prefix>_<test>_<pid>, removed when the test passes.
inline std::string scratch(const std::string& prefix, const std::string& test) {
  namespace fs = std::filesystem;
  const fs::path p = fs::temp_directory_path() / ("bbw_" + prefix + "_" + test + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  RemoveScratchOnPass::add(p.string());
  return p.string();
}

struct ProcessRun {
  bbw::runtime::ExitStatus status;
  std::string out, err, dir;
};

// Runs a command to completion, bounded by `limit` (then stopped), capturing its output in
// dir/<name>.stdout and .stderr.
inline ProcessRun run(const std::string& name, const std::vector<std::string>& argv, const std::string& dir,
                      std::chrono::seconds limit, const std::vector<std::string>& env = {}) {
  using namespace std::chrono_literals;
  std::filesystem::create_directories(dir);
  bbw::runtime::Child child(name, argv, dir + "/" + name + ".stdout", dir + "/" + name + ".stderr", env);
  auto status = child.wait_until(std::chrono::steady_clock::now() + limit);
  if (!status) status = child.stop(2000ms);
  return {*status, slurp(dir + "/" + name + ".stdout"), slurp(dir + "/" + name + ".stderr"), dir};
}

// A process (bbw_launch, bbw_intruder, ...) started now and not yet waited for, its output in
// dir/<name>.stdout and .stderr. Every wait is bounded.
class Launch {
 public:
  Launch(const std::string& dir, const std::string& name, const std::vector<std::string>& argv,
         const std::vector<std::string>& env = {})
      : dir_(dir), name_(name) {
    std::filesystem::create_directories(dir);
    child_ = std::make_unique<bbw::runtime::Child>(name, argv, stdout_file(), dir + "/" + name + ".stderr", env);
  }
  std::string stdout_file() const { return dir_ + "/" + name_ + ".stdout"; }
  std::string err() const { return slurp(dir_ + "/" + name_ + ".stderr"); }
  std::string out() const { return slurp(stdout_file()); }
  pid_t pid() const { return child_->pid(); }
  // Waits (bounded) until its stdout matches `re`; the first group ("" on timeout or its end).
  std::string wait_for_output(const std::regex& re, std::chrono::seconds limit) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < end) {
      std::smatch m;
      const std::string text = out();
      if (std::regex_search(text, m, re)) return m.size() > 1 ? m[1].str() : m[0].str();
      if (child_->wait_until(std::chrono::steady_clock::now() + std::chrono::milliseconds(20))) {
        std::smatch last;
        const std::string all = out();  // ended: one last look
        return std::regex_search(all, last, re) ? (last.size() > 1 ? last[1].str() : last[0].str()) : "";
      }
    }
    return "";
  }
  // The launcher's run id once printed ("bbw_launch: ..., run id <16 hex>, ..."; "" if never).
  std::string run_id(std::chrono::seconds limit = std::chrono::seconds(30)) { return wait_for_output(std::regex("run id ([0-9a-f]{16})"), limit); }
  bbw::runtime::ExitStatus wait(std::chrono::seconds limit) {
    auto st = child_->wait_until(std::chrono::steady_clock::now() + limit);
    if (!st) st = child_->stop(std::chrono::milliseconds(3000));
    return *st;
  }
  void signal(int sig) { child_->send_signal(sig); }
  // A bounded wait on its end: true when it has ended.
  bool ended_within(std::chrono::milliseconds d) {
    return child_->wait_until(std::chrono::steady_clock::now() + d).has_value();
  }

 private:
  std::string dir_, name_;
  std::unique_ptr<bbw::runtime::Child> child_;
};

// The Fast DDS 2.9 discovery abort (docs/faults.md, "Realtime restart"): a process that joins a
// domain where a participant has just died can abort in Fast DDS's own PDP code
// (`PDP.cpp:...: check_remote_participant_liveliness: Assertion ...`, an assertion left on in
// Debian's build; about 1 in 85 restarts here). Returns the .err file under out_dir that holds
// it, or "" when no process died of it. Tests that kill and restart processes run again on this
// one upstream failure only, and say so.
inline std::string fastdds_pdp_abort(const std::string& out_dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out_dir, ec)) {
    if (e.path().extension() != ".err") continue;
    const std::string text = slurp(e.path().string());
    if (text.find("PDP.cpp") != std::string::npos && text.find("Assertion") != std::string::npos) {
      return e.path().string();
    }
  }
  return "";
}

// One `"key": value` line of summary.json (our writer: one member per line): the key and the
// value, a string's quotes and the trailing comma removed. False when the line is no member.
inline bool member_line(const std::string& line, std::string& key, std::string& value) {
  const auto q1 = line.find('"');
  const auto q2 = line.find('"', q1 + 1);
  const auto colon = line.find(':', q2);
  if (q1 == std::string::npos || q2 == std::string::npos || colon == std::string::npos) return false;
  value = line.substr(colon + 1);
  value.erase(0, value.find_first_not_of(' '));
  while (!value.empty() && (value.back() == ',' || value.back() == ' ')) value.pop_back();
  if (value.size() >= 2 && value.front() == '"') value = value.substr(1, value.size() - 2);
  key = line.substr(q1 + 1, q2 - q1 - 1);
  return true;
}

// The objects of the array `array` in summary.json ("faults", "detections", "corners"): one map
// per object, string values unquoted. summary.json is written by our own writer, one key per line.
inline std::vector<std::map<std::string, std::string>> objects(const std::string& json, const std::string& array) {
  std::vector<std::map<std::string, std::string>> out;
  const auto a = json.find("\"" + array + "\": [");
  if (a == std::string::npos) return out;
  const auto end = json.find(']', a);
  std::size_t pos = a;
  while (true) {
    const auto open = json.find('{', pos);
    if (open == std::string::npos || open > end) break;
    const auto close = json.find('}', open);
    std::map<std::string, std::string> m;
    std::istringstream lines(json.substr(open + 1, close - open - 1));
    std::string line;
    while (std::getline(lines, line)) {
      std::string k, v;
      if (member_line(line, k, v)) m[k] = v;
    }
    out.push_back(m);
    pos = close + 1;
  }
  return out;
}

}  // namespace bbw::system_test
