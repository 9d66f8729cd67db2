// The in-process runner (node cores over the in-memory transport) against the committed digests
// of the lockstep logs that ./bbw run wrote over Fast DDS before the node-core redesign
// (data/lockstep_digests.txt): the behaviour did not change, and the in-memory transport runs
// the same protocol as the processes. SystemNodeEquivalence.* checks the DDS processes today.
// The process-fault scenarios (process_kill, ccu_kill) pin the in-process kill and restart
// against logs the DDS processes wrote with the launcher's kills and restarts.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <vector>

#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/node/csv_log.hpp"
#include "bbw/node/in_process.hpp"
#include "node_test_support.hpp"

namespace bbw::node {

namespace {

// scenario -> (log file -> sha256)
std::map<std::string, std::map<std::string, std::string>> pinned_digests() {
  std::ifstream in(test::source_path("tests/node/data/lockstep_digests.txt"));
  std::map<std::string, std::map<std::string, std::string>> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::string scenario, file, digest;
    s >> scenario >> file >> digest;
    out[scenario][file] = digest;
  }
  return out;
}

void run_logged(const std::string& scenario_rel, const std::string& dir) {
  const auto fs = faults::load_fault_scenario(test::source_path(scenario_rel));
  InProcessOptions o;
  o.schedule = fs.faults;
  o.process_faults = true;
  InProcessRun run(fs.scenario, test::robust_config(), o);
  CcuCsvLog ccu_log(dir, run.ccu());
  run.ccu().set_observer(&ccu_log);
  std::vector<std::unique_ptr<CornerPeriodsLog>> logs;
  for (std::size_t i = 0; i < run.corners(); ++i) {
    logs.push_back(std::make_unique<CornerPeriodsLog>(dir + "/corner_" + corner_name(run.corner(i).corner()) + "_periods.csv", 0));
    run.set_corner_observer(i, logs.back().get());  // every incarnation appends, as over DDS
  }
  run.run();
  run.ccu().set_observer(nullptr);
}

class NodeDigests : public ::testing::TestWithParam<std::string> {};

TEST_P(NodeDigests, InProcessLockstepLogsEqualThePinnedDdsLogs) {
  const auto pinned = pinned_digests();
  const auto it = pinned.find(GetParam());
  ASSERT_NE(it, pinned.end()) << GetParam() << " has no pinned digests";
  const std::string dir = (std::filesystem::temp_directory_path() /
                           ("bbw_node_digest_" + std::filesystem::path(GetParam()).stem().string() + "_" + std::to_string(::getpid())))
                              .string();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  run_logged(GetParam(), dir);
  for (const auto& [file, digest] : it->second) {
    EXPECT_EQ(test::sha256_of(dir + "/" + file), digest) << GetParam() << ": " << file << " differs from the pinned log";
  }
  std::filesystem::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Scenarios, NodeDigests,
                         ::testing::Values("config/scenarios/four_corner_rig.yaml", "config/scenarios/vehicle_stop.yaml",
                                           "config/scenarios/faults/fault_free_stop.yaml",
                                           "config/scenarios/faults/load_cell_bias.yaml",
                                           "config/scenarios/faults/network_silence.yaml",
                                           "config/scenarios/faults/network_delay.yaml",
                                           "config/scenarios/faults/resolver_offset.yaml",
                                           "config/scenarios/faults/actuator_seized.yaml",
                                           "config/scenarios/faults/process_kill.yaml",
                                           "config/scenarios/faults/ccu_kill.yaml"),
                         [](const ::testing::TestParamInfo<std::string>& p) {
                           return std::filesystem::path(p.param).stem().string();
                         });

TEST(InProcessRun, RefusesProcessFaultsUnlessAskedToCarryThemOut) {
  const auto fs = faults::load_fault_scenario(test::source_path("config/scenarios/faults/process_kill.yaml"));
  InProcessOptions o;
  o.schedule = fs.faults;
  EXPECT_THROW(InProcessRun(fs.scenario, test::robust_config(), o), std::invalid_argument);
  o.process_faults = true;
  EXPECT_NO_THROW(InProcessRun(fs.scenario, test::robust_config(), o));
}

TEST(InProcessRun, RefusesACcuRestartAsTheLauncherDoes) {
  const auto fs = faults::load_fault_scenario(test::source_path("config/scenarios/faults/ccu_kill.yaml"));
  InProcessOptions o;
  o.schedule = fs.faults;
  o.schedule.faults.at(0).restart_after_s = 0.5;
  o.process_faults = true;
  EXPECT_THROW(InProcessRun(fs.scenario, test::robust_config(), o), std::invalid_argument);
}

// process_kill.yaml: RR is killed at 11.0 s and restarted to rejoin at 11.5 s. As over DDS in
// lockstep (docs/faults.md, the DDS table): the CCU finds RR's writer gone at the end of the
// kill period (process_lost at 11.005 s) and runs on without it; the new incarnation starts at
// period 2300 from sequence 1; nothing is lost or received twice.
TEST(InProcessRun, AKilledCornerIsLostAtItsMissingBlockAndItsRestartRejoins) {
  const auto fs = faults::load_fault_scenario(test::source_path("config/scenarios/faults/process_kill.yaml"));
  InProcessOptions o;
  o.schedule = fs.faults;
  o.process_faults = true;
  InProcessRun run(fs.scenario, test::robust_config(), o);
  bool dead_seen = false;
  while (run.step()) {
    if (run.periods_done() == 2201) {
      EXPECT_EQ(run.incarnation(3), 1u);  // the launcher restarts it at once; it waits to rejoin
      EXPECT_FALSE(run.ccu().core().supervisor(3).view().available);
      dead_seen = true;
    }
  }
  EXPECT_TRUE(dead_seen);
  EXPECT_EQ(run.periods_done(), periods_of(fs.scenario));
  const CornerChannel& rr = run.ccu().channel(3);
  ASSERT_EQ(rr.corner, Corner::RR);
  EXPECT_EQ(rr.liveliness_lost, 1u);
  EXPECT_EQ(rr.rejoins, 1u);
  EXPECT_EQ(rr.incarnation, 1u);
  EXPECT_EQ(rr.samples_received, 11000u + 2500u);
  EXPECT_EQ(rr.block_gaps + rr.sample_gaps, 0u);
  EXPECT_EQ(rr.samples_invalid, 0u);
  EXPECT_EQ(run.corner(3).resume_step(), 2300u);
  EXPECT_EQ(run.corner(3).stats().samples_published, 2500u);
  EXPECT_EQ(run.ccu().core().supervisor(3).calibrator_restarts(), 1u);
  bool lost = false;
  for (const DetectionRecord& d : run.ccu().detections()) {
    EXPECT_EQ(d.slot, 3u) << faults::to_string(d.finding);
    if (d.finding == faults::Finding::ProcessLost) {
      lost = true;
      EXPECT_NEAR(d.detected_s, 11.005, 1e-9);
    }
  }
  EXPECT_TRUE(lost);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(run.ccu().channel(i).samples_received, 14000u);
    EXPECT_EQ(run.ccu().channel(i).block_gaps + run.ccu().channel(i).sample_gaps, 0u);
  }
}

// ccu_kill.yaml: the CCU dies at 11.0 s. Its last command is for period 2199; the corners find
// it gone instead of the grant of period 2200 and run on alone: hold, then the default force.
TEST(InProcessRun, AfterACcuKillTheCornersRunAloneUnderTheirWatchdog) {
  const auto fs = faults::load_fault_scenario(test::source_path("config/scenarios/faults/ccu_kill.yaml"));
  InProcessOptions o;
  o.schedule = fs.faults;
  o.process_faults = true;
  InProcessRun run(fs.scenario, test::robust_config(), o);
  run.run();
  EXPECT_FALSE(run.ccu_alive());
  EXPECT_EQ(run.periods_done(), periods_of(fs.scenario));
  for (std::size_t i = 0; i < run.corners(); ++i) {
    const CornerNode& c = run.corner(i);
    EXPECT_TRUE(c.ccu_lost());
    EXPECT_EQ(c.stats().periods, periods_of(fs.scenario));
    EXPECT_GT(c.stats().ccu_lost_s, 11.0);
    EXPECT_LT(c.stats().ccu_lost_s, 11.0 + o.watchdog.timeout_s + 0.001);
    EXPECT_NEAR(c.stats().default_force_s - c.stats().ccu_lost_s, o.watchdog.hold_s, 0.002);
    EXPECT_EQ(run.ccu().channel(i).blocks_received, 2200u);
  }
  EXPECT_TRUE(run.ccu().detections().empty());
}

// The hostile-channel hook on the corner -> CCU link: here it drops the last sample of every
// block, and the CCU counts one missing sample per block after the first.
TEST(InProcessRun, ABlockTapSeesAndMayChangeEveryBlock) {
  const auto fs = faults::load_fault_scenario(test::source_path("config/scenarios/vehicle_stop.yaml"));
  InProcessRun run(fs.scenario, test::robust_config(), InProcessOptions{});
  std::uint64_t tapped = 0;
  run.set_block_tap([&](std::size_t, msg::MeasurementBlock& b) {
    ++tapped;
    b.samples().pop_back();
  });
  run.run();
  const std::uint64_t periods = periods_of(fs.scenario);
  EXPECT_EQ(tapped, periods * run.corners());
  for (std::size_t i = 0; i < run.ccu().channels(); ++i) {
    const auto& ch = run.ccu().channel(i);
    EXPECT_EQ(ch.samples_received, periods * (steps_per_period(fs.scenario) - 1));
    EXPECT_EQ(ch.sample_gaps, periods - 1);
    EXPECT_EQ(ch.block_gaps, 0u);
  }
}

TEST(InProcessRun, EveryBlockAndSampleArrivesWithoutGaps) {
  const auto fs = faults::load_fault_scenario(test::source_path("config/scenarios/vehicle_stop.yaml"));
  InProcessRun run(fs.scenario, test::robust_config(), InProcessOptions{});
  run.run();
  EXPECT_EQ(run.periods_done(), periods_of(fs.scenario));
  for (std::size_t i = 0; i < run.ccu().channels(); ++i) {
    const auto& ch = run.ccu().channel(i);
    EXPECT_EQ(ch.blocks_received, run.periods_done());
    EXPECT_EQ(ch.samples_received, run.periods_done() * steps_per_period(fs.scenario));
    EXPECT_EQ(ch.block_gaps + ch.sample_gaps, 0u);
    EXPECT_EQ(run.corner(i).stats().samples_published, ch.samples_received);
    EXPECT_EQ(run.corner(i).stats().command_seq_gaps, 0u);
  }
}

}  // namespace

}  // namespace bbw::node
