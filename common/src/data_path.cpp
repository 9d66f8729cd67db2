#include "bbw/common/data_path.hpp"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace bbw::data {

namespace fs = std::filesystem;

std::string executable_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot read /proc/self/exe: " + ec.message());
  return exe.parent_path().string();
}

std::string path(const std::string& relative) {
  std::string tried;
  if (const char* env = std::getenv("BBW_DATA_DIR"); env != nullptr && *env != '\0') {
    const fs::path p = fs::path(env) / relative;
    if (fs::exists(p)) return p.string();
    tried = p.string() + " ($BBW_DATA_DIR)";
  }
  const fs::path p = (fs::path(executable_dir()) / ".." / "share" / "bbw" / relative).lexically_normal();
  if (fs::exists(p)) return p.string();
  tried += (tried.empty() ? "" : ", ") + p.string();
  throw std::runtime_error("cannot find bbw's " + relative + " (tried " + tried + "; set BBW_DATA_DIR to the folder holding config/)");
}

std::string root() { return fs::path(path("config")).parent_path().string(); }

}  // namespace bbw::data
