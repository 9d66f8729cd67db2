// `cmake --install` into a temporary prefix, then a scenario run from there, over Fast DDS and in
// memory: the installed binaries find their siblings and their data (config/) next to themselves
// (bbw/common/data_path.hpp), and no product binary holds a path into the source tree. Domain 142.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "system_test_support.hpp"

namespace {

using namespace std::chrono_literals;
using namespace bbw::system_test;
namespace fs = std::filesystem;

bool file_contains(const std::string& file, const std::string& needle) {
  std::ifstream in(file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return bytes.find(needle) != std::string::npos;
}

TEST(InstallTree, AScenarioRunsFromAnInstalledPrefix) {
  const std::string dir = scratch("install", "prefix");
  const std::string prefix = dir + "/prefix";
  const ProcessRun inst = run("cmake", {"/usr/bin/cmake", "--install", BBW_TEST_BINARY_DIR, "--prefix", prefix}, dir, 120s);
  ASSERT_TRUE(inst.status.ok()) << inst.status.describe() << "\n" << inst.out << inst.err;
  for (const char* b : {"bbw_launch", "bbw_ccu", "bbw_corner", "bbw_inproc", "bbw_calibrate", "bbw_analyze", "bbw_simulate"}) {
    const std::string file = prefix + "/bin/" + b;
    ASSERT_TRUE(fs::exists(file)) << file;
    EXPECT_FALSE(file_contains(file, BBW_TEST_SOURCE_DIR)) << b << " holds a path into the source tree " << BBW_TEST_SOURCE_DIR;
  }
  const std::string scenario = prefix + "/share/bbw/config/scenarios/vehicle_stop.yaml";
  ASSERT_TRUE(fs::exists(scenario));
  // Over Fast DDS: the launcher starts the installed CCU and corners, which read the installed
  // calibrator, monitor and DDS profiles.
  const ProcessRun dds = run("bbw_launch",
                             {prefix + "/bin/bbw_launch", scenario, "--out", dir + "/dds", "--mode", "lockstep", "--domain", "142",
                              "--no-report"},
                             dir, 150s, {"BBW_DATA_DIR=", "BBW_DDS_PROFILES="});
  ASSERT_TRUE(dds.status.ok()) << dds.status.describe() << "\n" << dds.out << dds.err;
  const ProcessRun mem = run("bbw_inproc", {prefix + "/bin/bbw_inproc", scenario, "--out", dir + "/memory"}, dir, 120s,
                             {"BBW_DATA_DIR="});
  ASSERT_TRUE(mem.status.ok()) << mem.status.describe() << "\n" << mem.out << mem.err;
  for (const char* f : {"ccu_FL.csv", "ccu_RR.csv", "ccu_periods.csv"}) {
    const std::string a = slurp(dir + "/dds/" + f), b = slurp(dir + "/memory/" + f);
    EXPECT_GT(a.size(), 1000u) << f;
    EXPECT_TRUE(a == b) << f << ": the installed DDS run and in-memory run differ";
  }
  fs::remove_all(dir);
}

}  // namespace
