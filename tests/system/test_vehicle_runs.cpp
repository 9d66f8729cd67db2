// Vehicle runs over Fast DDS (issue 15, docs/vehicle.md): bbw_launch starts the processes a
// vehicle scenario declares (bbw_ccu, four bbw_corner, bbw_vehicle, bbw_pedal) in lockstep; the
// vehicle's truth and the CCU's and corners' logs equal the in-process run's (bbw_vehicle_inproc)
// byte for byte, and summary.json carries the `vehicle` object. Domains 70-71.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "system_test_support.hpp"

namespace {

using namespace std::chrono_literals;
using namespace bbw::system_test;

std::string slurp(const std::string& file) {
  std::ifstream f(file);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Domain 70.
TEST(SystemVehicleRun, DryStopOverDdsEqualsTheInProcessRun) {
  const std::string dir = scratch("vehicle", "dry_dds");
  const std::string scenario = src("config/scenarios/vehicle/dry_straight_100kmh.yaml");
  const ProcessRun dds = run("bbw_launch",
                             {bin("bbw_launch"), scenario, "--out", dir + "/dds", "--domain", "70", "--discovery-timeout",
                              "20", "--no-report"},
                             dir, 150s);
  ASSERT_TRUE(dds.status.ok()) << dds.status.describe() << "\n" << dds.out << dds.err;
  const ProcessRun mem = run("bbw_vehicle_inproc", {bin("bbw_vehicle_inproc"), scenario, "--out", dir + "/mem", "--no-plots"},
                             dir, 120s);
  ASSERT_TRUE(mem.status.ok()) << mem.status.describe() << "\n" << mem.out << mem.err;
  const std::string truth_dds = slurp(dir + "/dds/vehicle_truth.csv");
  ASSERT_GT(truth_dds.size(), 100000u);  // 1400 periods
  EXPECT_TRUE(truth_dds == slurp(dir + "/mem/vehicle_truth.csv")) << "the DDS run's vehicle differs from the in-process run's";
  // The CCU's and the corners' logs too (the same node cores, the same lockstep protocol).
  for (const char* log : {"ccu_FL.csv", "ccu_RR.csv", "ccu_periods.csv", "corner_FL_periods.csv", "corner_RR_periods.csv"}) {
    const std::string d = slurp(dir + "/dds/" + log);
    EXPECT_FALSE(d.empty()) << log;
    EXPECT_TRUE(d == slurp(dir + "/mem/" + log)) << log << " differs between Fast DDS and in process";
  }
  EXPECT_NE(slurp(dir + "/dds/vehicle.out").find("1400 periods"), std::string::npos);
  EXPECT_NE(slurp(dir + "/dds/pedal.out").find("1400 periods"), std::string::npos);
  const std::string summary = slurp(dir + "/dds/summary.json");
  EXPECT_NE(summary.find("\"vehicle\":"), std::string::npos);
  EXPECT_NE(summary.find("\"stopping_distance_m\":"), std::string::npos);
  EXPECT_NE(summary.find("\"scenario\": \"dry_straight_100kmh\""), std::string::npos) << summary.substr(0, 300);
  std::filesystem::remove_all(dir);
}

// No DDS traffic: the launcher refuses before starting anything.
TEST(SystemVehicleRun, LauncherRefusesAVehicleScenarioInRealtime) {
  const std::string dir = scratch("vehicle", "realtime");
  const ProcessRun r = run("bbw_launch",
                           {bin("bbw_launch"), src("config/scenarios/vehicle/dry_straight_100kmh.yaml"), "--out", dir + "/out",
                            "--mode", "realtime", "--domain", "71"},
                           dir, 30s);
  EXPECT_TRUE(r.status.exited && r.status.code == 2) << r.status.describe();
  EXPECT_NE(r.err.find("lockstep only"), std::string::npos) << r.err;
  std::filesystem::remove_all(dir);
}

}  // namespace
