#include "bbw/dds/shm_cleanup.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <system_error>

namespace bbw::dds {

namespace fs = std::filesystem;

namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Holds flock(LOCK_EX) on a file until destroyed; locked() false when someone else holds it.
class ExclusiveProbe {
 public:
  explicit ExclusiveProbe(const fs::path& file) {
    fd_ = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ >= 0 && ::flock(fd_, LOCK_EX | LOCK_NB) == 0) locked_ = true;
  }
  ~ExclusiveProbe() {
    if (fd_ >= 0) ::close(fd_);  // closing releases the lock
  }
  ExclusiveProbe(const ExclusiveProbe&) = delete;
  ExclusiveProbe& operator=(const ExclusiveProbe&) = delete;
  bool locked() const { return locked_; }

 private:
  int fd_ = -1;
  bool locked_ = false;
};

bool older_than(const fs::path& file, std::chrono::seconds min_age) {
  std::error_code ec;
  const auto mtime = fs::last_write_time(file, ec);
  if (ec) return true;  // vanished meanwhile: nothing to protect
  return fs::file_time_type::clock::now() - mtime >= min_age;
}

// Every file under `dir` that some process maps (from /proc/<pid>/maps). A process whose maps
// this user may not read (in a container: its pid 1) is taken not to map them: a user's own
// Fast DDS processes are always readable to it.
std::set<std::string> mapped_files(const std::string& dir) {
  std::set<std::string> out;
  std::error_code ec;
  const std::string prefix = fs::path(dir).lexically_normal().string() + "/";
  for (const auto& entry : fs::directory_iterator("/proc", ec)) {
    const std::string pid = entry.path().filename().string();
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream maps(entry.path() / "maps");
    std::string line;
    while (maps && std::getline(maps, line)) {
      const auto at = line.find(prefix);
      if (at == std::string::npos) continue;
      std::string path = line.substr(at);
      if (const auto del = path.find(" (deleted)"); del != std::string::npos) path.resize(del);
      out.insert(path);
    }
  }
  return out;
}

}  // namespace

ShmCleanupReport cleanup_stale_shm(const std::string& dir, std::chrono::seconds min_age) {
  ShmCleanupReport report;
  // Group lock files by the resource they guard: base -> its lock files.
  std::map<std::string, std::vector<std::string>> groups;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("fastrtps_", 0) != 0) continue;
    for (const char* suffix : {"_el", "_sl"}) {
      if (ends_with(name, suffix)) {
        groups[name.substr(0, name.size() - 3)].push_back(name);
      }
    }
  }
  const fs::path root(dir);
  // Files with no lock file at all: a port whose lock files are gone (Fast DDS 2.9 leaves
  // fastrtps_portN and sem.fastrtps_portN_mutex behind that way) or a segment left so. Nobody
  // can hold a lock on them, so they are stale when no process maps them and they are old.
  std::vector<std::string> orphans;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    std::string base;
    if (name.rfind("fastrtps_", 0) == 0 && !ends_with(name, "_el") && !ends_with(name, "_sl")) {
      base = name;
    } else if (name.rfind("sem.fastrtps_", 0) == 0 && ends_with(name, "_mutex")) {
      base = name.substr(4, name.size() - 4 - 6);
    } else {
      continue;
    }
    if (groups.count(base) == 0) orphans.push_back(name);
  }
  if (!orphans.empty()) {
    const auto mapped = mapped_files(dir);
    // Segments first: a semaphore is mapped only while its port is being opened, so it goes
    // only with a segment that goes too (or that no longer exists).
    std::set<std::string> kept_segments;
    std::stable_partition(orphans.begin(), orphans.end(), [](const std::string& n) { return n.rfind("sem.", 0) != 0; });
    for (const auto& name : orphans) {
      const bool semaphore = name.rfind("sem.", 0) == 0;
      const std::string segment = semaphore ? name.substr(4, name.size() - 4 - 6) : name;
      const std::string path = (fs::path(dir).lexically_normal() / name).string();
      if (mapped.count(path) > 0 || (semaphore && kept_segments.count(segment) > 0)) {
        ++report.kept_live;
        if (!semaphore) kept_segments.insert(segment);
      } else if (!older_than(root / name, min_age)) {
        ++report.kept_young;
        if (!semaphore) kept_segments.insert(segment);
      } else if (fs::remove(root / name, ec)) {
        report.removed.push_back(name);
      }
    }
  }
  for (const auto& [base, locks] : groups) {
    // Stale only when every lock file of the resource can be locked exclusively by us.
    std::vector<std::unique_ptr<ExclusiveProbe>> held;
    bool live = false;
    for (const auto& lock : locks) {
      held.push_back(std::make_unique<ExclusiveProbe>(root / lock));
      if (!held.back()->locked()) live = true;
    }
    if (live) {
      ++report.kept_live;
      continue;
    }
    bool young = false;
    for (const auto& lock : locks) young = young || !older_than(root / lock, min_age);
    if (fs::exists(root / base, ec)) young = young || !older_than(root / base, min_age);
    if (young) {
      ++report.kept_young;
      continue;
    }
    // Remove the resource first, then its semaphore, then the lock files (still held by us).
    for (const std::string& victim : {base, "sem." + base + "_mutex"}) {
      if (fs::remove(root / victim, ec)) report.removed.push_back(victim);
    }
    for (const auto& lock : locks) {
      if (fs::remove(root / lock, ec)) report.removed.push_back(lock);
    }
  }
  return report;
}

}  // namespace bbw::dds
