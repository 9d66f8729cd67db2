// Helpers shared by the system tests: paths into the trees this test was built from, a scratch
// folder per test, and running a process to completion with a deadline.
#pragma once

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bbw/launch/child.hpp"

namespace bbw::system_test {

inline std::string src(const std::string& rel) { return std::string(BBW_TEST_SOURCE_DIR) + "/" + rel; }
inline std::string bin(const std::string& name) { return std::string(BBW_TEST_BINARY_DIR) + "/bin/" + name; }

inline std::string slurp(const std::string& file) {
  std::ifstream f(file);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// A fresh, empty folder /tmp/bbw_<prefix>_<test>_<pid>.
inline std::string scratch(const std::string& prefix, const std::string& test) {
  namespace fs = std::filesystem;
  const fs::path p = fs::temp_directory_path() / ("bbw_" + prefix + "_" + test + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

struct ProcessRun {
  bbw::launch::ExitStatus status;
  std::string out, err, dir;
};

// Runs a command to completion, bounded by `limit` (then stopped), capturing its output in
// dir/<name>.stdout and .stderr.
inline ProcessRun run(const std::string& name, const std::vector<std::string>& argv, const std::string& dir,
                      std::chrono::seconds limit, const std::vector<std::string>& env = {}) {
  using namespace std::chrono_literals;
  std::filesystem::create_directories(dir);
  bbw::launch::Child child(name, argv, dir + "/" + name + ".stdout", dir + "/" + name + ".stderr", env);
  auto status = child.wait_until(std::chrono::steady_clock::now() + limit);
  if (!status) status = child.stop(2000ms);
  return {*status, slurp(dir + "/" + name + ".stdout"), slurp(dir + "/" + name + ".stderr"), dir};
}

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

}  // namespace bbw::system_test
