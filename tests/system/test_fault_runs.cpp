// Fault campaigns over the real processes (bbw_launch -> bbw_ccu + four bbw_corner over Fast
// DDS on loopback; docs/faults.md, "Over DDS"). Each test uses its own DDS domain id (noted per
// test) so ctest -j runs them in parallel; every run is bounded by the launcher and here.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "bbw/common/csv.hpp"
#include "bbw/runtime/child.hpp"
#include "system_test_support.hpp"
#include "bbw/runtime/stats_file.hpp"

namespace {

using namespace std::chrono_literals;
using namespace bbw::system_test;
namespace fs = std::filesystem;



std::string scratch(const std::string& test) { return bbw::system_test::scratch("faults", test); }

using LaunchRun = bbw::system_test::ProcessRun;

// Runs the launcher; on the Fast DDS 2.9 discovery abort (and only on it: any other failure is
// returned as it is) the run is repeated, at most twice, with a note in the test's output.
// Realtime runs go under SCHED_FIFO 10 as root (at_realtime_priority, inherited by every process the
// launcher starts, a restarted corner too), as the failover tests' do: their criteria are wall
// clock (a loss found within 50 ms, a restarted corner back before 2.5 s). At normal priority,
// beside a sanitizer build, the restarted corner of SystemFaultsRealtime once came back only at
// 2.76 s.
LaunchRun launch(const std::string& scenario, const std::string& dir, int domain, const std::string& mode) {
  std::vector<std::string> argv{bin("bbw_launch"), src(scenario), "--out", dir + "/out", "--mode", mode, "--domain",
                                 std::to_string(domain), "--discovery-timeout", "20", "--no-report"};
  if (mode == "realtime") argv = at_realtime_priority(std::move(argv));
  for (int attempt = 1;; ++attempt) {
    LaunchRun r = run("bbw_launch", argv, dir, 170s);
    const std::string abort_file = r.status.ok() ? "" : fastdds_pdp_abort(dir + "/out");
    if (abort_file.empty() || attempt == 3) return r;
    std::cout << "[ NOTE     ] run " << attempt << " of " << scenario
              << " hit the Fast DDS 2.9 discovery assertion (docs/faults.md), in " << abort_file
              << "; running it again\n";
    fs::remove_all(dir + "/out");
  }
}


double num(const std::map<std::string, std::string>& m, const std::string& k) {
  const auto it = m.find(k);
  EXPECT_NE(it, m.end()) << "missing key " << k;
  return it == m.end() ? 0.0 : std::stod(it->second);
}

struct Case {
  friend void PrintTo(const Case& c, std::ostream* os) { *os << c.scenario << " on domain " << c.domain; }
  const char* scenario;  // under config/scenarios/faults/
  int domain;
};

// A corner restarted once, from the run's outputs: on every corner the samples published were
// received, with no gap and none rejected; the CCU saw one rejoin and restarted the corner's
// calibrator once; in the CCU's log of that corner every sample time appears once and in
// order, and the numbering restarts at 1 once: after the last sample before the kill (within
// kill_tol_s of kill_s) the next is the new process's first, in [first_min_s, first_max_s].
// Realtime (exact_calibrator_restarts false): a period that comes later than the 15 ms deadline
// on this shared machine is a short link loss after which the calibrator restarts again, so
// there it restarts at least once. And there only the measurement samples must be gap-free:
// the summary's sequence_gaps also counts block numbers and command numbers, and under load
// (two busy loops on both cores, 2 of 20 runs) the restarted corner once missed 2 commands
// (the CCU's keep-last command history moved on before the new reader acknowledged; a corner
// follows the newest command anyway) and once the CCU counted a block-number gap with every
// sample received in order. Returns the number of rows in that log.
std::size_t expect_one_clean_restart(const std::string& out, const std::string& corner, double kill_s,
                                     double kill_tol_s, double first_min_s, double first_max_s,
                                     bool exact_calibrator_restarts) {
  for (const auto& c : objects(slurp(out + "/summary.json"), "corners")) {
    EXPECT_EQ(num(c, "samples_published"), num(c, "samples_received")) << c.at("corner");
    EXPECT_EQ(num(c, exact_calibrator_restarts ? "sequence_gaps" : "sample_gaps"), 0.0) << c.at("corner");
    EXPECT_EQ(num(c, "samples_rejected_by_guard"), 0.0) << c.at("corner");
  }
  const std::string ccu = out + "/ccu.stats";
  const auto st = bbw::runtime::read_stats(ccu);
  EXPECT_EQ(bbw::runtime::stat_number(st, corner + ".rejoins", ccu), 1.0);
  if (exact_calibrator_restarts) {
    EXPECT_EQ(bbw::runtime::stat_number(st, corner + ".calibrator_restarts", ccu), 1.0);
  } else {
    EXPECT_GE(bbw::runtime::stat_number(st, corner + ".calibrator_restarts", ccu), 1.0);
  }
  bbw::csv::ReadOptions o;
  o.required = {"time_s", "seq"};
  const auto t = bbw::csv::read(out + "/ccu_" + corner + ".csv", o);
  const auto& time = t.column("time_s");
  const auto& seq = t.column("seq");
  int restarts = 0;
  for (std::size_t i = 1; i < t.rows(); ++i) {
    EXPECT_GT(time[i], time[i - 1]) << "row " << i;
    if (time[i] <= time[i - 1]) break;
    if (seq[i] != seq[i - 1] + 1) {
      ++restarts;
      EXPECT_EQ(seq[i], 1.0);
      EXPECT_NEAR(time[i - 1], kill_s, kill_tol_s);
      EXPECT_GE(time[i], first_min_s - 1e-9);
      EXPECT_LE(time[i], first_max_s + 1e-9);
    }
  }
  EXPECT_EQ(restarts, 1);
  return t.rows();
}

class LockstepFault : public ::testing::TestWithParam<Case> {};

// Domains 170-182 and 188: each fault type runs through the launcher in lockstep; every injected fault
// is detected and diagnosed right, and nothing else is raised on any corner.
TEST_P(LockstepFault, IsDetectedAndDiagnosedRight) {
  const Case c = GetParam();
  const std::string dir = scratch(c.scenario);
  const LaunchRun r = launch("config/scenarios/faults/" + std::string(c.scenario) + ".yaml", dir, c.domain, "lockstep");
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
  const std::string summary = slurp(dir + "/out/summary.json");
  const auto faults = objects(summary, "faults");
  const auto detections = objects(summary, "detections");
  ASSERT_FALSE(faults.empty()) << summary;
  for (const auto& f : faults) {
    EXPECT_EQ(f.at("detected"), "true") << f.at("corner") << " " << f.at("type");
    EXPECT_EQ(f.at("correct"), "true") << f.at("corner") << " " << f.at("type") << ": diagnosis " << f.at("diagnosis");
    EXPECT_GE(num(f, "latency_ms"), 0.0);
    EXPECT_LT(num(f, "latency_ms"), 500.0) << f.at("type");  // drift is the slowest (~380 ms)
    if (f.at("part") == "load_cell" && f.at("type") == "bias") {
      EXPECT_LE(num(f, "latency_ms"), 100.0);
    }
    if (f.at("corner") == "CCU") continue;
    for (const auto& d : detections) {
      EXPECT_EQ(d.at("corner"), f.at("corner")) << "a fault raised on another corner: " << d.at("finding");
    }
  }
  if (std::string(c.scenario) == "ccu_kill") {
    EXPECT_NE(summary.find("\"ended_by_injected_ccu_kill\": true"), std::string::npos) << summary;
    EXPECT_TRUE(detections.empty());
    for (const auto& corner : objects(summary, "corners")) {
      // Every corner's watchdog found the CCU lost 20 ms after its last command.
      EXPECT_NEAR(num(corner, "ccu_lost_detected_s"), 11.016, 0.011) << corner.at("corner");
    }
    // The corners kept braking: the default clamp force (8 kN) each, never released.
    bbw::csv::ReadOptions o;
    o.required = {"time_s", "force_true_kN", "watchdog_mode"};
    for (const char* k : {"FL", "FR", "RL", "RR"}) {
      const auto t = bbw::csv::read(dir + "/out/corner_" + std::string(k) + "_periods.csv", o);
      const auto& time = t.column("time_s");
      const auto& f = t.column("force_true_kN");
      const auto& mode = t.column("watchdog_mode");
      ASSERT_NEAR(time.back(), 14.0, 1e-6) << k;
      EXPECT_EQ(mode.back(), 3.0) << k << ": not in the default state at the end";
      EXPECT_GT(f.back(), 6.0) << k << ": released after the CCU died";
    }
  }
  if (std::string(c.scenario) == "actuator_seized") {
    // Found lost at once (current without motion), named not releasing once told to release.
    ASSERT_EQ(faults.size(), 1u);
    EXPECT_EQ(faults[0].at("diagnosis"), "actuator_not_releasing") << summary;
    bool named = false;
    for (const auto& d : detections) named = named || d.at("finding") == "actuator_not_releasing";
    EXPECT_TRUE(named) << summary;
  }
  if (std::string(c.scenario) == "process_kill") {
    // The restart: RR's second process joined at 11.5 s; no sample lost or applied twice.
    EXPECT_EQ(expect_one_clean_restart(dir + "/out", "RR", 11.0, 1e-9, 11.501, 11.501, true), 13500u);
  }
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    EveryFaultType, LockstepFault,
    ::testing::Values(Case{"load_cell_bias", 170}, Case{"load_cell_drift", 171}, Case{"load_cell_stuck", 172},
                      Case{"load_cell_noise_burst", 173}, Case{"load_cell_dropout", 174}, Case{"resolver_offset", 175},
                      Case{"resolver_stuck", 176}, Case{"actuator_torque_loss", 177}, Case{"actuator_total_loss", 178}, Case{"actuator_seized", 188},
                      Case{"network_silence", 179}, Case{"network_delay", 180}, Case{"process_kill", 181},
                      Case{"ccu_kill", 182}),
    [](const ::testing::TestParamInfo<Case>& i) { return std::string(i.param.scenario); });

// Domains 183, 184: fault-free scenarios raise nothing over DDS either.
TEST(SystemFaults, FaultFreeRunsRaiseNoFault) {
  int domain = 183;
  for (const char* s : {"config/scenarios/faults/fault_free_stop.yaml", "config/scenarios/vehicle_stop.yaml"}) {
    const std::string dir = scratch("fault_free_" + std::to_string(domain));
    const LaunchRun r = launch(s, dir, domain++, "lockstep");
    ASSERT_TRUE(r.status.ok()) << s << ": " << r.status.describe() << "\n" << r.out << r.err;
    const std::string summary = slurp(dir + "/out/summary.json");
    EXPECT_TRUE(objects(summary, "detections").empty()) << s << "\n" << summary;
    EXPECT_TRUE(objects(summary, "faults").empty()) << s;
    for (const auto& corner : objects(summary, "corners")) {
      EXPECT_EQ(num(corner, "samples_rejected_by_guard"), 0.0) << s << " " << corner.at("corner");
      EXPECT_LT(num(corner, "ccu_lost_detected_s"), 0.0) << s << " " << corner.at("corner");
    }
    fs::remove_all(dir);
  }
}

// Domain 186: in real time, a silenced corner (FR) and a killed corner (RR) are detected within
// 50 ms (DDS deadline 15 ms on the measurements); the dead process is named once its
// participant's discovery lease (2 s) has run out.
TEST(SystemFaultsRealtime, KilledAndSilencedCornersDetectedWithin50ms) {
  const std::string dir = scratch("realtime");
  const LaunchRun r = launch("tests/system/data/rt_kill_silence.yaml", dir, 186, "realtime");
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
  const std::string summary = slurp(dir + "/out/summary.json");
  const auto faults = objects(summary, "faults");
  ASSERT_EQ(faults.size(), 2u) << summary;
  for (const auto& f : faults) {
    EXPECT_EQ(f.at("detected"), "true") << f.at("corner");
    EXPECT_GT(num(f, "latency_ms"), 0.0) << f.at("corner");
    EXPECT_LT(num(f, "latency_ms"), 50.0) << f.at("corner") << " " << f.at("type");
    EXPECT_EQ(f.at("correct"), "true") << f.at("corner") << ": " << f.at("diagnosis");
  }
  EXPECT_EQ(faults[0].at("diagnosis"), "link_lost");
  EXPECT_EQ(faults[1].at("diagnosis"), "process_lost");
  fs::remove_all(dir);
}

// Domain 187: in real time, RR's process is killed at 1.0 s and restarted 0.5 s later. The
// loss is detected within 50 ms (as a lost link: nothing tells a dead process from a cut link
// that fast); the restarted process's first samples (a new incarnation) name the process, long
// before the 2 s lease would have. Its new samples flow with no gap, none rejected, its
// calibrator restarts once from the last good curve.
TEST(SystemFaultsRealtime, ARestartedCornerIsNamedAsAProcessLossAndRejoins) {
  const std::string dir = scratch("realtime_restart");
  const LaunchRun r = launch("tests/system/data/rt_restart.yaml", dir, 187, "realtime");
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
  const std::string summary = slurp(dir + "/out/summary.json");
  const auto faults = objects(summary, "faults");
  ASSERT_EQ(faults.size(), 1u) << summary;
  const auto& f = faults[0];
  EXPECT_EQ(f.at("detected"), "true");
  EXPECT_LT(num(f, "latency_ms"), 50.0);
  EXPECT_EQ(f.at("diagnosis"), "process_lost");
  EXPECT_EQ(f.at("correct"), "true");
  EXPECT_GE(num(f, "diagnosis_s"), 1.5) << "named before the new process joined";
  EXPECT_LT(num(f, "diagnosis_s"), 2.5) << "named by the lease, not by the restart";
  // On the other corners at most a late period (link_lost, when this shared machine stalls a
  // process beyond the 15 ms deadline, or its 30 ms liveliness lease lapses); never a sensor,
  // actuator or process finding. On a failure the whole summary (each corner's
  // measurement_liveliness_lost, deadlines, gaps) says which way the CCU lost it.
  for (const auto& d : objects(summary, "detections")) {
    if (d.at("corner") != "RR") {
      EXPECT_EQ(d.at("finding"), "link_lost") << d.at("corner") << "\n" << summary;
    }
  }
  // Realtime: the last sample before the kill is within a period of 1.0 s; the new process
  // starts at the CCU's current period once it has joined (1.531-1.641 s in 8 runs), never
  // before 1.5 s.
  EXPECT_GT(expect_one_clean_restart(dir + "/out", "RR", 1.0, 0.0051, 1.501, 2.5, false), 2000u);
  bbw::csv::ReadOptions o;
  o.required = {"time_s"};
  const auto time = bbw::csv::read(dir + "/out/ccu_RR.csv", o).column("time_s");
  EXPECT_NEAR(time.back(), 3.5, 1e-6);
  fs::remove_all(dir);
}

}  // namespace
