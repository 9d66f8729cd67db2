// The real processes (bbw_launch -> bbw_ccu + four bbw_corner) over Fast DDS on loopback.
// Each test uses its own DDS domain id (noted per test) so ctest -j runs them in parallel.
// Every run is bounded: the launcher has a discovery deadline and a wall-time bound, and each
// child is waited on with a deadline here.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/calibration/offline.hpp"
#include "bbw/common/csv.hpp"
#include "bbw/faults/corner_supervisor.hpp"
#include "bbw/node/ccu_core.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/runtime/child.hpp"
#include "bbw/runtime/run_stats.hpp"
#include "bbw/runtime/stats_file.hpp"
#include "system_test_support.hpp"

namespace {

using namespace std::chrono_literals;
using namespace bbw::system_test;
namespace fs = std::filesystem;



std::string scratch(const std::string& test) { return bbw::system_test::scratch("system", test); }

ProcessRun launch(const std::string& scenario, const std::string& dir, int domain, const std::string& mode,
           const std::vector<std::string>& env = {}) {
  return run("bbw_launch",
             {bin("bbw_launch"), src(scenario), "--out", dir + "/out", "--mode", mode, "--domain",
              std::to_string(domain), "--discovery-timeout", "20", "--no-report"},
             dir, 150s, env);
}

double stat(const std::string& file, const std::string& key) {
  return bbw::runtime::stat_number(bbw::runtime::read_stats(file), key, file);
}

// Domain 160.
TEST(SystemLockstep, FiveProcessesCompleteWithoutGapsOrLostSamples) {
  const std::string dir = scratch("lockstep");
  const ProcessRun r = launch("tests/system/data/short_rig.yaml", dir, 160, "lockstep");
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
  const std::string out = dir + "/out";
  const std::string ccu = out + "/ccu.stats";
  EXPECT_EQ(stat(ccu, "periods_done"), 800.0);
  EXPECT_EQ(stat(ccu, "measurement_samples_lost"), 0.0);
  for (const char* c : {"FL", "FR", "RL", "RR"}) {
    const std::string p = std::string(c) + ".";
    const std::string cs = out + "/corner_" + c + ".stats";
    EXPECT_EQ(stat(cs, "samples_published"), 4000.0) << c;
    EXPECT_EQ(stat(ccu, p + "samples_received"), 4000.0) << c;
    EXPECT_EQ(stat(ccu, p + "blocks_received"), 800.0) << c;
    EXPECT_EQ(stat(ccu, p + "sample_gaps"), 0.0) << c;
    EXPECT_EQ(stat(ccu, p + "block_gaps"), 0.0) << c;
    EXPECT_EQ(stat(cs, "command_seq_gaps"), 0.0) << c;
    EXPECT_EQ(stat(cs, "commands_applied"), 800.0) << c;
    EXPECT_GT(stat(ccu, p + "fits_accepted"), 0.0) << c << ": the calibrator never fitted";
  }
  // The same files through the typed structs the launcher reads them with (every key known).
  const auto typed = bbw::runtime::load_ccu_stats(ccu);
  EXPECT_EQ(typed.periods_done, 800u);
  EXPECT_EQ(typed.corners.size(), 4u);
  EXPECT_EQ(bbw::runtime::load_corner_stats(out + "/corner_RR.stats").samples_published, 4000u);
  const std::string summary = slurp(out + "/summary.json");
  EXPECT_NE(summary.find("\"samples_lost\": 0"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"sequence_gaps\": 0"), std::string::npos) << summary;
  // A rig run has no clamp-force command: its tracking errors are null with the reason, never
  // 0; its estimate was scored (the reason is null).
  EXPECT_EQ(summary.find("\"tracking_rms_error_kN\": 0"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"tracking_rms_error_kN\": null"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"tracking_not_scored_reason\": \"no sample was under a clamp-force command\""),
            std::string::npos) << summary;
  EXPECT_NE(summary.find("\"not_scored_reason\": null"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("\"estimate_max_abs_error_kN\": null"), std::string::npos) << summary;
  fs::remove_all(dir);
}

// Domain 167: a scenario that declares its processes (two corners) gets exactly those: the
// CCU's barrier waits for two corners, every period completes, and no other corner ran.
TEST(SystemLockstep, TheLauncherStartsWhatTheScenarioDeclares) {
  const std::string dir = scratch("declared");
  const ProcessRun r = launch("tests/system/data/two_corner_rig.yaml", dir, 167, "lockstep");
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
  const std::string out = dir + "/out";
  EXPECT_NE(r.out.find("3 processes"), std::string::npos) << r.out;
  const auto typed = bbw::runtime::load_ccu_stats(out + "/ccu.stats");
  EXPECT_EQ(typed.periods_done, 400u);
  EXPECT_EQ(typed.corners.size(), 2u);
  for (const char* c : {"FL", "RR"}) {
    EXPECT_EQ(stat(out + "/corner_" + std::string(c) + ".stats", "commands_applied"), 400.0) << c;
  }
  for (const char* c : {"FR", "RL"}) EXPECT_FALSE(fs::exists(out + "/corner_" + std::string(c) + ".stats")) << c;
  std::string summary = slurp(out + "/summary.json");
  summary.erase(std::remove_if(summary.begin(), summary.end(), [](unsigned char ch) { return std::isspace(ch) != 0; }),
                summary.end());
  EXPECT_NE(summary.find("\"processes_started\":[\"ccu\",\"FL\",\"RR\"]"), std::string::npos) << summary;
  // A declared list that leaves a corner out is refused before anything starts.
  std::string text = slurp(src("tests/system/data/two_corner_rig.yaml"));
  text.replace(text.find("processes: [ccu, FL, RR]"), 24, "processes: [ccu, FL]    ");
  text.replace(text.find("../../../config/plant/"), 22, src("config/plant/"));
  const std::string bad = dir + "/missing_rr.yaml";
  std::ofstream(bad) << text;
  const ProcessRun refused = run("bbw_launch", {bin("bbw_launch"), bad, "--out", dir + "/bad", "--mode", "lockstep", "--domain", "167", "--no-report"},
                                 dir, 60s);
  EXPECT_EQ(refused.status.code, 2) << refused.status.describe() << "\n" << refused.err;
  EXPECT_NE(refused.err.find("missing_rr.yaml:10: key 'processes': corner RR of this scenario has no process"), std::string::npos)
      << refused.err;
  if (!HasFailure()) fs::remove_all(dir);
}

// Domains 161 and 162: the same scenario and seed twice give byte-identical logs.
TEST(SystemLockstep, TwoRunsProduceIdenticalLogs) {
  const std::string dir_a = scratch("twice_a");
  const std::string dir_b = scratch("twice_b");
  const ProcessRun a = launch("tests/system/data/short_stop.yaml", dir_a, 161, "lockstep");
  ASSERT_TRUE(a.status.ok()) << a.status.describe() << "\n" << a.err;
  const ProcessRun b = launch("tests/system/data/short_stop.yaml", dir_b, 162, "lockstep");
  ASSERT_TRUE(b.status.ok()) << b.status.describe() << "\n" << b.err;
  for (const char* c : {"FL", "FR", "RL", "RR"}) {
    const std::string la = slurp(dir_a + "/out/ccu_" + std::string(c) + ".csv");
    const std::string lb = slurp(dir_b + "/out/ccu_" + std::string(c) + ".csv");
    ASSERT_GT(la.size(), 1000u) << c;
    EXPECT_TRUE(la == lb) << "corner " << c << ": logs differ between two lockstep runs";
  }
  fs::remove_all(dir_a);
  fs::remove_all(dir_b);
}

// Domain 163: the CCU's calibrator fed over DDS equals the offline calibrator on the same
// corner's recording, bit for bit (the log holds the inputs at full precision).
TEST(SystemLockstep, CcuEstimatesEqualOfflineCalibration) {
  const std::string dir = scratch("offline");
  const ProcessRun r = launch("tests/system/data/short_rig.yaml", dir, 163, "lockstep");
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.err;
  // The CCU starts each corner's calibrator from its caliper's end-of-line test (the scenario's
  // plant: its curve, its keys, its position constants; faults::calibrator_start with the corner's
  // monitor parameters): offline starts from the same, and so does ./bbw calibrate, given that
  // start as a config file (calibration::to_yaml, every number at full precision).
  const auto scenario = bbw::scenario::load_scenario(src("tests/system/data/short_rig.yaml"));
  const auto base = bbw::calibration::load_config(src("config/calibrator/robust.yaml"));
  const auto start_of = [&](std::size_t corner) {
    return bbw::faults::calibrator_start(
        base, bbw::ccu::corner_monitor_params(scenario, corner, bbw::ccu::monitor_params_for(scenario)));
  };
  for (const char* c : {"FL", "RR"}) {
    const std::size_t corner = std::string(c) == "FL" ? 0 : 3;
    ASSERT_EQ(scenario.corners.at(corner).name, c);
    const auto config = start_of(corner);
    ASSERT_FALSE(config.initial_stiffness_kN_per_rev.empty()) << "the CCU's start has the caliper's keys";
    const std::string config_file = dir + "/robust_from_end_of_line_" + std::string(c) + ".yaml";
    std::ofstream(config_file) << bbw::calibration::to_yaml(config);
    bbw::csv::ReadOptions o;
    o.required = {"time_s", "position_rev", "force_internal_kN", "estimate_kN", "friction_kN", "curve_kN"};
    const auto log = bbw::csv::read(dir + "/out/ccu_" + std::string(c) + ".csv", o);
    ASSERT_EQ(log.lines_rejected, 0u) << log.rejection_summary();
    ASSERT_EQ(log.rows(), 4000u);
    bbw::calibration::Recording rec;
    rec.time_s = log.column("time_s");
    rec.position_rev = log.column("position_rev");
    rec.force_kN = log.column("force_internal_kN");
    const auto offline = bbw::calibration::run_recording(config, rec);
    ASSERT_GT(offline.stats.fits_accepted, 0u) << c;
    const auto& est = log.column("estimate_kN");
    const auto& fric = log.column("friction_kN");
    const auto& curve = log.column("curve_kN");
    std::size_t differing = 0;
    for (std::size_t i = 0; i < log.rows(); ++i) {
      if (est[i] != offline.estimates[i].force_kN || fric[i] != offline.estimates[i].friction_kN ||
          curve[i] != offline.estimates[i].curve_force_kN) {
        ++differing;
      }
    }
    EXPECT_EQ(differing, 0u) << "corner " << c << ": estimates over DDS differ from offline";
    // And the command-line tool on the same recording agrees at its output precision.
    const std::string cal_dir = dir + "/calibrate_" + c;
    const ProcessRun cal = run("bbw_calibrate", {bin("bbw_calibrate"), "--input", dir + "/out/ccu_" + std::string(c) + ".csv",
                                          "--config", config_file, "--out", cal_dir, "--truth", "force_true_kN"},
                        dir + "/cal_" + c, 60s);
    ASSERT_TRUE(cal.status.ok()) << cal.err;
    bbw::csv::ReadOptions oo;
    oo.required = {"estimate_kN"};
    const auto tool = bbw::csv::read(cal_dir + "/estimates.csv", oo);
    ASSERT_EQ(tool.rows(), log.rows());
    std::size_t tool_diff = 0;
    for (std::size_t i = 0; i < tool.rows(); ++i) {
      char buf[64];
      std::snprintf(buf, sizeof(buf), "%.9g", est[i]);
      if (std::strtod(buf, nullptr) != tool.column("estimate_kN")[i]) ++tool_diff;
    }
    EXPECT_EQ(tool_diff, 0u) << "corner " << c << ": ./bbw calibrate disagrees with the CCU";
  }
  fs::remove_all(dir);
}

// Domain 164: a short realtime run completes and reports deadline misses and jitter.
TEST(SystemRealtime, ShortRunCompletesAndReportsDeadlineMisses) {
  const std::string dir = scratch("realtime");
  const ProcessRun r = launch("tests/system/data/short_stop.yaml", dir, 164, "realtime");
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
  const std::string out = dir + "/out";
  EXPECT_EQ(stat(out + "/ccu.stats", "periods_done"), 400.0);
  EXPECT_GE(stat(out + "/ccu.stats", "measurement_deadlines_missed"), 0.0);
  const std::string summary = slurp(out + "/summary.json");
  EXPECT_NE(summary.find("\"measurement_deadline_misses\""), std::string::npos);
  EXPECT_NE(summary.find("\"max_jitter_s\""), std::string::npos);
  EXPECT_NE(summary.find("\"mode\": \"realtime\""), std::string::npos);
  const double wall = stat(out + "/ccu.stats", "wall_s");
  EXPECT_GT(wall, 1.9) << "a realtime run of 2 s cannot finish faster than the wall clock";
  EXPECT_LT(wall, 5.0);
  fs::remove_all(dir);
}

// Domain 165 (never reached: argument and config errors stop before any DDS entity).
TEST(SystemMisuse, UnknownCornerNameExitsWithUsageError) {
  const std::string dir = scratch("misuse_corner");
  const ProcessRun r = run("bbw_corner", {bin("bbw_corner"), "--corner", "XX", "--scenario", src("tests/system/data/short_rig.yaml"),
                                   "--domain", "165"}, dir, 20s);
  EXPECT_TRUE(r.status.exited);
  EXPECT_EQ(r.status.code, 2);
  EXPECT_NE(r.err.find("unknown corner 'XX'"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

TEST(SystemMisuse, BrokenScenarioExitsWithUsageErrorNamingTheFile) {
  const std::string dir = scratch("misuse_scenario");
  const ProcessRun r = run("bbw_corner", {bin("bbw_corner"), "--corner", "FL", "--scenario", src("tests/system/data/broken.yaml"),
                                   "--domain", "165"}, dir, 20s);
  EXPECT_EQ(r.status.code, 2) << r.status.describe();
  EXPECT_NE(r.err.find("broken.yaml"), std::string::npos) << r.err;
  const ProcessRun c = run("bbw_ccu", {bin("bbw_ccu"), "--scenario", src("tests/system/data/broken.yaml"), "--domain", "165"}, dir, 20s);
  EXPECT_EQ(c.status.code, 2) << c.status.describe();
  EXPECT_NE(c.err.find("broken.yaml"), std::string::npos) << c.err;
  const ProcessRun l = run("bbw_launch", {bin("bbw_launch"), src("tests/system/data/broken.yaml"), "--out", dir + "/out"}, dir, 20s);
  EXPECT_EQ(l.status.code, 2) << l.status.describe();
  fs::remove_all(dir);
}

// Domain 166: a corner that fails to start is named by the launcher, which stops the rest.
TEST(SystemMisuse, LauncherNamesACornerThatFailsToStart) {
  const std::string dir = scratch("misuse_launch");
  const auto t0 = std::chrono::steady_clock::now();
  const ProcessRun r = launch("tests/system/data/short_rig.yaml", dir, 166, "lockstep", {"BBW_LAUNCH_CORNER_BIN=/bin/false"});
  EXPECT_FALSE(r.status.ok());
  EXPECT_NE(r.err.find("bbw_corner"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("failed: exit 1"), std::string::npos) << r.err;
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 15s) << "the launcher should not wait for discovery to time out";
  fs::remove_all(dir);
}

}  // namespace
