// The in-process runner (node cores over the in-memory transport) against the committed digests
// of the lockstep logs that ./bbw run wrote over Fast DDS before the node-core redesign
// (data/lockstep_digests.txt): the behaviour did not change, and the in-memory transport runs
// the same protocol as the processes. SystemNodeEquivalence.* checks the DDS processes today.
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
  InProcessRun run(fs.scenario, test::robust_config(), o);
  CcuCsvLog ccu_log(dir, run.ccu());
  run.ccu().set_observer(&ccu_log);
  std::vector<std::unique_ptr<CornerPeriodsLog>> logs;
  for (std::size_t i = 0; i < run.corners(); ++i) {
    logs.push_back(std::make_unique<CornerPeriodsLog>(dir + "/corner_" + corner_name(run.corner(i).corner()) + "_periods.csv", 0));
    run.corner(i).set_observer(logs.back().get());
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
                                           "config/scenarios/faults/actuator_seized.yaml"),
                         [](const ::testing::TestParamInfo<std::string>& p) {
                           return std::filesystem::path(p.param).stem().string();
                         });

TEST(InProcessRun, RefusesProcessFaults) {
  const auto fs = faults::load_fault_scenario(test::source_path("config/scenarios/faults/process_kill.yaml"));
  InProcessOptions o;
  o.schedule = fs.faults;
  EXPECT_THROW(InProcessRun(fs.scenario, test::robust_config(), o), std::invalid_argument);
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
