// Stale Fast DDS shared-memory files are removed only when no live process holds their lock
// and they are old enough; files a live process holds are never touched.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "bbw/dds/shm_cleanup.hpp"

namespace fs = std::filesystem;

namespace {

class ShmDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("bbw_shm_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void touch(const std::string& name, bool old) {
    std::ofstream(dir_ / name) << "x";
    if (old) fs::last_write_time(dir_ / name, fs::file_time_type::clock::now() - std::chrono::minutes(5));
  }
  bool exists(const std::string& name) const { return fs::exists(dir_ / name); }
  fs::path dir_;
};

TEST_F(ShmDir, RemovesDeadOwnersFilesAndKeepsLiveAndYoungOnes) {
  // Dead segment and dead port: lock files nobody holds, old.
  touch("fastrtps_dead", true);
  touch("fastrtps_dead_el", true);
  touch("fastrtps_port7411", true);
  touch("fastrtps_port7411_el", true);
  touch("fastrtps_port7411_sl", true);
  touch("sem.fastrtps_port7411_mutex", true);
  // Live segment: old, but its lock is held (as a live Fast DDS owner would).
  touch("fastrtps_live", true);
  touch("fastrtps_live_el", true);
  const int fd = ::open((dir_ / "fastrtps_live_el").c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  // Live port: a user holds the shared lock.
  touch("fastrtps_port7413", true);
  touch("fastrtps_port7413_el", true);
  touch("fastrtps_port7413_sl", true);
  const int fd_sh = ::open((dir_ / "fastrtps_port7413_sl").c_str(), O_RDONLY);
  ASSERT_EQ(::flock(fd_sh, LOCK_SH | LOCK_NB), 0);
  // Young unlocked segment: a process may be creating it right now.
  touch("fastrtps_young", false);
  touch("fastrtps_young_el", false);
  // Not ours at all.
  touch("other_program_segment", true);

  const auto report = bbw::dds::cleanup_stale_shm(dir_.string(), std::chrono::seconds(5));

  EXPECT_FALSE(exists("fastrtps_dead"));
  EXPECT_FALSE(exists("fastrtps_dead_el"));
  EXPECT_FALSE(exists("fastrtps_port7411"));
  EXPECT_FALSE(exists("fastrtps_port7411_el"));
  EXPECT_FALSE(exists("fastrtps_port7411_sl"));
  EXPECT_FALSE(exists("sem.fastrtps_port7411_mutex"));
  EXPECT_TRUE(exists("fastrtps_live"));
  EXPECT_TRUE(exists("fastrtps_live_el"));
  EXPECT_TRUE(exists("fastrtps_port7413"));
  EXPECT_TRUE(exists("fastrtps_port7413_sl"));
  EXPECT_TRUE(exists("fastrtps_young"));
  EXPECT_TRUE(exists("other_program_segment"));
  EXPECT_EQ(report.kept_live, 2u);
  EXPECT_EQ(report.kept_young, 1u);
  EXPECT_EQ(report.removed.size(), 6u);
  ::close(fd);
  ::close(fd_sh);
}

}  // namespace

namespace {

// Fast DDS 2.9 leaves port segments and their semaphores with no lock file (issue 17: 8 of
// each after a killed CCU). Nobody maps them: stale once old. A mapped one is live.
TEST_F(ShmDir, RemovesOrphanPortFilesNobodyMapsAndKeepsMappedOnes) {
  touch("fastrtps_port7511", true);
  touch("sem.fastrtps_port7511_mutex", true);
  touch("fastrtps_port7513", false);  // young
  touch("fastrtps_port7515", true);   // mapped by this process: live
  touch("sem.fastrtps_port7515_mutex", true);  // not mapped, but its port is live: kept
  const int fd = ::open((dir_ / "fastrtps_port7515").c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  void* map = ::mmap(nullptr, 1, PROT_READ, MAP_SHARED, fd, 0);
  ASSERT_NE(map, MAP_FAILED);

  const auto report = bbw::dds::cleanup_stale_shm(dir_.string(), std::chrono::seconds(2));

  EXPECT_FALSE(exists("fastrtps_port7511"));
  EXPECT_FALSE(exists("sem.fastrtps_port7511_mutex"));
  EXPECT_TRUE(exists("fastrtps_port7513"));
  EXPECT_TRUE(exists("fastrtps_port7515"));
  EXPECT_TRUE(exists("sem.fastrtps_port7515_mutex"));
  EXPECT_EQ(report.removed.size(), 2u);
  EXPECT_EQ(report.kept_young, 1u);
  EXPECT_EQ(report.kept_live, 2u);
  ::munmap(map, 1);
  ::close(fd);
}

}  // namespace
