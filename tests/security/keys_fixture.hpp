// Runs `scripts/bbw-keys.sh` into a fresh temporary directory and removes it afterwards; plus a
// shell helper that captures a command's exit status and output.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <stdlib.h>
#include <sys/wait.h>

namespace bbw::test {

struct Shell {
  int status = -1;
  std::string output;  // stdout and stderr
};

inline Shell run_shell(const std::string& command) {
  Shell r;
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  const int s = ::pclose(p);
  r.status = WIFEXITED(s) ? WEXITSTATUS(s) : -1;
  return r;
}

inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline std::string source_dir() {
  const char* s = std::getenv("BBW_SOURCE_DIR");
  return s != nullptr ? s : BBW_TEST_SOURCE_DIR;
}

inline std::string keys_script() { return source_dir() + "/scripts/bbw-keys.sh"; }

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A temporary directory with a complete key set, made once per test suite.
class TempKeys {
 public:
  TempKeys() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "bbw_keys_XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    dir_ = tmpl;
    const Shell r = run_shell(quote(keys_script()) + " " + quote(dir_.string()));
    status_ = r.status;
    output_ = r.output;
  }
  ~TempKeys() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  TempKeys(const TempKeys&) = delete;
  TempKeys& operator=(const TempKeys&) = delete;

  const std::filesystem::path& dir() const { return dir_; }
  std::string path(const std::string& rel) const { return (dir_ / rel).string(); }
  int status() const { return status_; }
  const std::string& output() const { return output_; }

 private:
  std::filesystem::path dir_;
  int status_ = -1;
  std::string output_;
};

}  // namespace bbw::test
