// Vehicle runs over Fast DDS (issue 15, docs/vehicle.md): bbw_launch starts the processes a
// vehicle scenario declares (bbw_ccu, four bbw_corner, bbw_vehicle, bbw_pedal) in lockstep; the
// vehicle's truth and the CCU's and corners' logs equal the in-process run's (bbw_vehicle_inproc)
// byte for byte, and summary.json carries the `vehicle` object; so do they with a corner's process
// killed in ABS braking. Domains 70-72.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
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

// One vehicle scenario over Fast DDS (DIR/dds, on `domain`) and in process (DIR/mem); asserts
// both ran, that the DDS run's vehicle truth (1400 periods at least) and `logs` equal the
// in-process run's byte for byte, and returns the launcher's run.
ProcessRun dds_equals_in_process(const std::string& dir, const std::string& scenario, int domain,
                                 std::initializer_list<const char*> logs) {
  const ProcessRun dds = run("bbw_launch",
                             {bin("bbw_launch"), scenario, "--out", dir + "/dds", "--domain", std::to_string(domain),
                              "--discovery-timeout", "20", "--no-report"},
                             dir, 150s);
  EXPECT_TRUE(dds.status.ok()) << dds.status.describe() << "\n" << dds.out << dds.err;
  const ProcessRun mem = run("bbw_vehicle_inproc", {bin("bbw_vehicle_inproc"), scenario, "--out", dir + "/mem", "--no-plots"},
                             dir, 120s);
  EXPECT_TRUE(mem.status.ok()) << mem.status.describe() << "\n" << mem.out << mem.err;
  const std::string truth_dds = slurp(dir + "/dds/vehicle_truth.csv");
  EXPECT_GT(truth_dds.size(), 100000u);  // 1400 periods
  EXPECT_TRUE(truth_dds == slurp(dir + "/mem/vehicle_truth.csv")) << "the DDS run's vehicle differs from the in-process run's";
  for (const char* log : logs) {
    const std::string d = slurp(dir + "/dds/" + log);
    EXPECT_FALSE(d.empty()) << log;
    EXPECT_TRUE(d == slurp(dir + "/mem/" + log)) << log << " differs between Fast DDS and in process";
  }
  return dds;
}

// Domain 70.
TEST(SystemVehicleRun, DryStopOverDdsEqualsTheInProcessRun) {
  const std::string dir = scratch("vehicle", "dry_dds");
  // The CCU's and the corners' logs too (the same node cores, the same lockstep protocol).
  const ProcessRun dds = dds_equals_in_process(dir, src("config/scenarios/vehicle/dry_straight_100kmh.yaml"), 70,
                                               {"ccu_FL.csv", "ccu_RR.csv", "ccu_periods.csv", "corner_FL_periods.csv",
                                                "corner_RR_periods.csv"});
  if (HasFailure()) return;
  EXPECT_NE(slurp(dir + "/dds/vehicle.out").find("1400 periods"), std::string::npos);
  EXPECT_NE(slurp(dir + "/dds/pedal.out").find("1400 periods"), std::string::npos);
  const std::string summary = slurp(dir + "/dds/summary.json");
  EXPECT_NE(summary.find("\"vehicle\":"), std::string::npos);
  EXPECT_NE(summary.find("\"stopping_distance_m\":"), std::string::npos);
  EXPECT_NE(summary.find("\"scenario\": \"dry_straight_100kmh\""), std::string::npos) << summary.substr(0, 300);
  std::filesystem::remove_all(dir);
}

// Domain 72. The shipped lost-corner scenario (FL's process killed 0.8 s in, 0.5 s into ABS
// braking) over Fast DDS: the CCU and the vehicle learn the loss from the corner's writers' lost
// liveliness while they wait for its period in lockstep, the vehicle's e-caliper releases, and
// the run is the in-process one byte for byte.
TEST(SystemVehicleRun, ALostCornerOverDdsEqualsTheInProcessRun) {
  const std::string dir = scratch("vehicle", "lost_dds");
  const ProcessRun dds = dds_equals_in_process(dir, src("config/scenarios/vehicle/dry_fault_FL_lost_abs.yaml"), 72,
                                               {"ccu_FL.csv", "ccu_FR.csv", "ccu_periods.csv", "corner_RR_periods.csv"});
  if (HasFailure()) return;
  EXPECT_NE(dds.out.find("killed bbw_corner FL as scheduled at 0.8 s"), std::string::npos) << dds.out;
  // The CCU took FL out of use: its last logged sample is at the kill, the periods run to the end.
  const std::string fl = slurp(dir + "/dds/ccu_FL.csv");
  const std::string last = fl.substr(fl.rfind('\n', fl.size() - 2) + 1);
  EXPECT_LT(std::stod(last.substr(0, last.find(','))), 0.81) << last;
  EXPECT_NE(slurp(dir + "/dds/vehicle.out").find("1400 periods"), std::string::npos);
  std::filesystem::remove_all(dir);
}

// No DDS traffic: a restarted corner has no lockstep rejoin with the vehicle, so a vehicle
// scenario's process faults are kills only; the launcher refuses a restart before starting anything.
TEST(SystemVehicleRun, LauncherRefusesARestartInAVehicleScenario) {
  const std::string dir = scratch("vehicle", "restart");
  std::filesystem::create_directories(dir);
  // The lost-corner calipers with a restart after the kill, and the scenario pointing at them
  // (every relative path made absolute into the tree).
  std::string corners = slurp(src("config/scenarios/vehicle/corners/calipers_FL_lost.yaml"));
  const std::string kill = "  - {at_s: 0.8, corner: FL, part: process, type: kill}";
  ASSERT_NE(corners.find(kill), std::string::npos);
  corners.insert(corners.find(kill) + kill.size(), "\n  - {at_s: 2.0, corner: FL, part: process, type: restart}");
  const std::string plant = "\nplant: ../../../plant/ecaliper.yaml";
  ASSERT_NE(corners.find(plant), std::string::npos);
  corners.replace(corners.find(plant), plant.size(), "\nplant: " + src("config/plant/ecaliper.yaml"));
  std::ofstream(dir + "/calipers_restart.yaml") << corners;
  std::string text = slurp(src("config/scenarios/vehicle/dry_fault_FL_lost_abs.yaml"));
  const std::string corners_key = "\ncorners: corners/calipers_FL_lost.yaml";
  ASSERT_NE(text.find(corners_key), std::string::npos);
  text.replace(text.find(corners_key), corners_key.size(), "\ncorners: " + dir + "/calipers_restart.yaml");
  for (const std::string key : {"vehicle: ", "brake_control: "}) {
    const auto p = text.find("\n" + key) + 1;
    text.insert(p + key.size(), src("config/scenarios/vehicle") + "/");
  }
  const std::string file = dir + "/restart.yaml";
  std::ofstream(file) << text;
  const ProcessRun r = run("bbw_launch", {bin("bbw_launch"), file, "--out", dir + "/out", "--domain", "72"}, dir, 30s);
  EXPECT_TRUE(r.status.exited && r.status.code == 2) << r.status.describe() << "\n" << r.out << r.err;
  // The calipers' file, its line and key, and the rule (a vehicle scenario's process faults are kills).
  EXPECT_NE(r.err.find("calipers_restart.yaml:29: key 'faults[1].type': must be one of {kill}"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/out/summary.json"));
  std::filesystem::remove_all(dir);
}

// scripts/vehicle-population.py (docs/vehicle.md, eleventh part), a small subset: four drawn
// laden cars, one per surface, run in process; the table names every draw and each surface's
// worst; population.json holds the drawn cars and their figures; the same seed draws the same
// cars; a second call resumes (runs nothing again: the same figures). No DDS.
TEST(SystemVehicleRun, APopulationOfLadenCarsIsDrawnRunAndResumed) {
  const std::string dir = scratch("vehicle", "population");
  const std::vector<std::string> argv{"/usr/bin/python3", src("scripts/vehicle-population.py"), dir + "/pop", "--draws", "4",
                                      "--seed", "7", "--jobs", "2"};
  const std::vector<std::string> env{"BBW_BUILD_DIR=" + std::string(BBW_TEST_BINARY_DIR)};
  const ProcessRun first = run("population", argv, dir, 300s, env);
  ASSERT_TRUE(first.status.ok()) << first.status.describe() << "\n" << first.out << first.err;
  for (const char* draw : {"vp_000_dry", "vp_001_wet", "vp_002_snow", "vp_003_ice"}) {
    EXPECT_NE(first.out.find("| " + std::string(draw) + " |"), std::string::npos) << draw << "\n" << first.out;
    EXPECT_TRUE(std::filesystem::exists(dir + "/pop/runs/" + draw + "/summary.json")) << draw;
  }
  EXPECT_NE(first.out.find("| ice | 1 (0 not stopped) |"), std::string::npos) << first.out;
  EXPECT_NE(first.err.find("4/4 stops"), std::string::npos) << first.err;  // progress
  const std::string json = slurp(dir + "/pop/population.json");
  EXPECT_NE(json.find("\"payload_kg\""), std::string::npos);
  EXPECT_NE(json.find("\"distance_ratio\""), std::string::npos);
  // Resumed: nothing is run again, the same table comes out.
  const auto stamp = std::filesystem::last_write_time(dir + "/pop/runs/vp_000_dry/summary.json");
  const ProcessRun again = run("population_again", argv, dir, 120s, env);
  ASSERT_TRUE(again.status.ok()) << again.status.describe() << "\n" << again.err;
  EXPECT_EQ(again.out, first.out);
  EXPECT_TRUE(std::filesystem::last_write_time(dir + "/pop/runs/vp_000_dry/summary.json") == stamp);
  // Bad input: a clear error and a non-zero exit.
  const ProcessRun bad = run("population_bad", {"/usr/bin/python3", src("scripts/vehicle-population.py"), dir + "/bad", "--draws", "0"},
                             dir, 60s, env);
  EXPECT_TRUE(bad.status.exited && bad.status.code != 0) << bad.status.describe();
  EXPECT_NE(bad.err.find("--draws and --jobs must be at least 1"), std::string::npos) << bad.err;
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
