// A hot-standby CCU's parts without processes (issue 16): the corner's record of whose commands
// it took (runtime::CommandOwnerTracker), the failover stats files, the ownership strength rule,
// the summary's `failover` arithmetic, and the launcher's output folder with a standby's files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <unistd.h>

#include "bbw/dds/topics.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/node/command_plan.hpp"
#include "bbw/runtime/command_owner.hpp"
#include "bbw/runtime/failover_stats.hpp"
#include "failover_summary.hpp"
#include "options.hpp"
#include "out_dir.hpp"

namespace {

using namespace bbw;
using runtime::CommandRole;

TEST(CommandOwnerTracker, RecordsChangesOfWriterAndTheLongestGaps) {
  runtime::CommandOwnerTracker t(0.005);
  t.on_command(CommandRole::Standby, 0, 0.0, 100.000);  // the start: the standby's came first
  t.on_command(CommandRole::Primary, 0, 0.0, 100.001);
  for (std::uint64_t k = 1; k <= 10; ++k) t.on_command(CommandRole::Primary, k, 0.005 * k, 100.001 + 0.005 * k);
  // The primary stops after period 10; the standby's command for period 13 comes 17 ms later.
  t.on_command(CommandRole::Standby, 13, 0.065, 100.051 + 0.017);
  t.on_command(CommandRole::Standby, 14, 0.070, 100.073);
  const auto& s = t.stats();
  EXPECT_EQ(s.commands_primary, 11u);
  EXPECT_EQ(s.commands_standby, 3u);
  ASSERT_EQ(s.switches.size(), 3u);
  EXPECT_EQ(s.switches[0].from, "none");
  EXPECT_EQ(s.switches[0].to, "standby");
  EXPECT_EQ(s.switches[1].to, "primary");
  EXPECT_EQ(s.switches[2].from, "primary");
  EXPECT_EQ(s.switches[2].to, "standby");
  EXPECT_EQ(s.switches[2].step, 13u);
  EXPECT_NEAR(s.switches[2].gap_ms, 17.0, 1e-6);
  EXPECT_NEAR(s.max_gap_mono_ms, 17.0, 1e-6);
  EXPECT_DOUBLE_EQ(s.max_gap_mono_at_sim_s, 0.065);
  EXPECT_NEAR(s.max_gap_sim_ms, 15.0, 1e-9);  // three periods
  EXPECT_THROW(runtime::CommandOwnerTracker(0.0), std::invalid_argument);
  // Lockstep: the standby's repeat of a period the corner has done (taken again after the
  // primary was killed at its next period) is counted, but the takeover is its first new grant.
  runtime::CommandOwnerTracker l(0.005, true);
  for (std::uint64_t k = 0; k < 700; ++k) l.on_command(CommandRole::Primary, k, 0.005 * k, 100.0 + 0.001 * k);
  l.on_command(CommandRole::Standby, 699, 3.495, 100.754);  // a repeat, 54 ms after the last grant
  l.on_command(CommandRole::Standby, 700, 3.5, 100.756);
  const auto ls = l.stats();
  EXPECT_EQ(ls.commands_standby, 2u);
  ASSERT_EQ(ls.switches.size(), 2u);
  EXPECT_EQ(ls.switches[1].step, 700u);
  EXPECT_NEAR(ls.switches[1].gap_ms, 57.0, 1e-6);
  EXPECT_NEAR(ls.max_gap_sim_ms, 5.0, 1e-9);
}

TEST(FailoverStats, RoundTripAndNameWhatIsWrong) {
  runtime::CcuFailoverStats c;
  c.role = "primary";
  c.strength_initial = dds::ccu_strength(true, 0);
  c.strength_final = dds::ccu_strength(true, 1);
  c.failure = "hang";
  c.failed_sim_s = 3.5;
  c.failed_mono_s = 1234.5;
  c.outages = 1;
  c.demote_reason = "resumed after a stop";
  c.stalls = 3;  // the first two recorded
  c.stall_intervals = {{100.25, 100.5}, {200.0, 200.0125}};
  const auto back = runtime::parse_ccu_failover(runtime::to_text(c), "x.stats");
  EXPECT_EQ(back.role, "primary");
  EXPECT_EQ(back.strength_final, c.strength_final);
  EXPECT_EQ(back.demote_reason, "resumed after a stop");
  EXPECT_DOUBLE_EQ(back.failed_sim_s, 3.5);
  ASSERT_EQ(back.stall_intervals.size(), 2u);
  EXPECT_DOUBLE_EQ(back.stall_intervals[1].to_mono_s, 200.0125);
  std::string more = runtime::to_text(c);
  more.replace(more.find("stalls=3"), 8, "stalls=1");  // more intervals than stalls
  try {
    runtime::parse_ccu_failover(more, "w.stats");
    FAIL() << "more stall intervals than stalls must be an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("w.stats: key 'stall_intervals'"), std::string::npos) << e.what();
  }
  runtime::CornerFailoverStats k;
  k.corner = "FL";
  k.switches.push_back({"none", "primary", 0, 0.0, 10.0, 0.0});
  k.switches.push_back({"primary", "standby", 700, 3.5, 13.5, 15.0});
  // A corner's own stall: its late periods, caught up one after another, merge into one.
  runtime::note_corner_stall(k, 0.060, 20.060);
  runtime::note_corner_stall(k, 0.055, 20.0601);
  runtime::note_corner_stall(k, 0.012, 30.0);
  ASSERT_EQ(k.stalls, 2u);
  EXPECT_DOUBLE_EQ(k.stall_intervals[0].from_mono_s, 20.0);
  EXPECT_DOUBLE_EQ(k.stall_intervals[0].to_mono_s, 20.0601);
  const auto kb = runtime::parse_corner_failover(runtime::to_text(k), "y.stats");
  ASSERT_EQ(kb.stall_intervals.size(), 2u);
  EXPECT_DOUBLE_EQ(kb.stall_intervals[1].from_mono_s, 29.988);
  ASSERT_EQ(kb.switches.size(), 2u);
  EXPECT_EQ(kb.switches[1].to, "standby");
  EXPECT_DOUBLE_EQ(kb.switches[1].gap_ms, 15.0);
  try {
    runtime::parse_ccu_failover("role=primary\n", "z.stats");
    FAIL() << "a missing key must be an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("z.stats: key 'strength_initial' is missing"), std::string::npos) << e.what();
  }
  std::string bad = runtime::to_text(c);
  bad.replace(bad.find("role=primary"), 12, "role=boss");
  EXPECT_THROW(runtime::parse_ccu_failover(bad, "z.stats"), std::runtime_error);
}

TEST(OwnershipStrength, FewerOutagesLeadThenThePrimary) {
  EXPECT_GT(dds::ccu_strength(true, 0), dds::ccu_strength(false, 0));   // the primary leads
  EXPECT_LT(dds::ccu_strength(true, 1), dds::ccu_strength(false, 0));   // until its first outage
  EXPECT_GT(dds::ccu_strength(true, 1), dds::ccu_strength(false, 1));   // an outage both had
  EXPECT_LT(dds::ccu_strength(false, 2), dds::ccu_strength(true, 1));
  EXPECT_GT(dds::ccu_strength(true, 5000000), 0u);                      // never 0 or wrapped
  EXPECT_LT(dds::ccu_strength(true, 5000000), dds::ccu_strength(true, 999998));
}

// A scenario with a constant demand, and corner logs built from it.
struct Synthetic {
  faults::FaultScenario fs = faults::load_fault_scenario(std::string(BBW_TEST_SOURCE_DIR) +
                                                         "/config/scenarios/faults/ccu_failover_kill.yaml");
  launch::FailoverInput in;
  Synthetic() {
    in.scenario = &fs.scenario;
    in.lockstep = false;
    in.primary.role = "primary";
    in.standby.role = "standby";
    in.primary.failure = "kill";
    in.primary.failed_sim_s = 3.5;
    in.primary.failed_mono_s = 103.5;
    const bbw::ccu::CommandPlanner planner(fs.scenario);
    for (std::size_t i = 0; i < 4; ++i) {
      launch::FailoverCornerInput c;
      c.owners.corner = fs.scenario.corners[i].name;
      c.owners.switches.push_back({"none", "primary", 0, 0.0, 100.0, 0.0});
      c.owners.switches.push_back({"primary", "standby", 702, 3.51, 103.5 + 0.004 * (i + 1), 14.0});
      c.owners.max_gap_mono_ms = 14.0;
      c.owners.max_gap_sim_ms = 5.0;
      for (int k = 1; k <= 1000; ++k) {
        const double t = 0.005 * k;
        c.periods.emplace_back(t, planner.at(i, t - 0.005).clamp_force_kN - 0.3);  // a standing error
      }
      in.corners.push_back(c);
    }
  }
};

TEST(FailoverSummary, TakeoverGapDipAndOwners) {
  Synthetic s;
  // FR's force falls 0.4 kN below its usual tracking for one period after the failure.
  for (auto& [t, f] : s.in.corners[1].periods) {
    if (std::fabs(t - 3.6) < 1e-9) f -= 0.4;
  }
  const auto r = launch::assess_failover(s.in);
  EXPECT_EQ(r.failure, "kill");
  EXPECT_DOUBLE_EQ(r.failed_s, 3.5);
  EXPECT_EQ(r.takeover_missing, "");
  EXPECT_NEAR(r.takeover_ms, 16.0, 1e-6);  // the slowest corner, RR
  EXPECT_NEAR(r.takeover_gap_ms, 14.0, 1e-9);
  EXPECT_NEAR(r.max_force_dip_kN, 0.4, 1e-6);  // the standing 0.3 kN is not the failover's
  EXPECT_NEAR(r.max_tracking_error_before_kN, 0.3, 1e-6);
  EXPECT_EQ(r.owners_at_end, "standby,standby,standby,standby");
  EXPECT_EQ(r.switches_after_failure, 4);
  EXPECT_EQ(r.switches_back_to_primary, 0);
  EXPECT_FALSE(r.safe_state_entered);
  // A corner that never took the standby's command: no takeover time, and it is named.
  s.in.corners[2].owners.switches.pop_back();
  const auto missing = launch::assess_failover(s.in);
  EXPECT_EQ(missing.takeover_missing, "RL");
  EXPECT_LT(missing.takeover_ms, 0.0);
  // Lockstep: simulated time.
  Synthetic l;
  l.in.lockstep = true;
  const auto ls = launch::assess_failover(l.in);
  EXPECT_NEAR(ls.takeover_ms, 10.0, 1e-6);  // period 702 starts 10 ms after 3.5 s
  EXPECT_NEAR(ls.takeover_wall_ms, 16.0, 1e-6);
  EXPECT_DOUBLE_EQ(ls.max_command_gap_ms, 5.0);
}

// A loaded lockstep run flaps hundreds of times before the failure: each corner keeps its first
// changes of owner and its latest (the takeover among them) and counts those between; the summary
// still finds the takeover and counts every change before the failure. (With only the first 64
// kept, a secure lockstep kill run under six busy loops reported its takeover missing.)
TEST(FailoverSummary, OwnershipFlappingBeforeTheFailureKeepsTheTakeover) {
  using T = runtime::CommandOwnerTracker;
  auto flapping = [](const std::string& corner, int flaps, double takeover_mono_s) {
    T t(0.005);
    std::uint64_t k = 0;
    for (int i = 0; i < flaps; ++i, ++k) {
      t.on_command(i % 2 == 0 ? CommandRole::Primary : CommandRole::Standby, k, 0.005 * k, 100.0 + 0.001 * k);
    }
    t.on_command(CommandRole::Primary, k, 0.005 * k, 100.0 + 0.001 * k);  // the primary owns it at the failure
    t.on_command(CommandRole::Standby, 702, 3.51, takeover_mono_s);      // the takeover
    auto st = t.stats();
    st.corner = corner;
    return runtime::parse_corner_failover(runtime::to_text(st), corner + ".stats");  // as the launcher reads it
  };
  Synthetic s;  // the primary fails at 103.5 s (monotonic)
  const int flaps = 300;
  for (std::size_t i = 0; i < 4; ++i) s.in.corners[i].owners = flapping(s.in.corners[i].owners.corner, flaps, 103.5 + 0.004 * (i + 1));
  const auto& fl = s.in.corners[0].owners;
  ASSERT_EQ(fl.switches.size(), T::kKeepFirst + T::kKeepLast);
  EXPECT_EQ(fl.switches_dropped, static_cast<std::uint64_t>(flaps + 2) - T::kKeepFirst - T::kKeepLast);  // none->primary ... ->standby
  for (std::size_t j = 1; j < fl.switches.size(); ++j) EXPECT_LT(fl.switches[j - 1].step, fl.switches[j].step) << j;
  const auto r = launch::assess_failover(s.in);
  EXPECT_EQ(r.takeover_missing, "");
  EXPECT_NEAR(r.takeover_ms, 16.0, 1e-6);
  EXPECT_EQ(r.switches_before_failure, 4 * flaps);  // all but the start's first change, per corner
  EXPECT_EQ(r.switches_after_failure, 4);
  EXPECT_EQ(r.owners_at_end, "standby,standby,standby,standby");
  // Flapping on after the failure too, beyond what is kept: who owned RL at the failure is not
  // known, and the summary says so instead of guessing.
  Synthetic late;
  for (std::size_t i = 0; i < 4; ++i) late.in.corners[i].owners = flapping(late.in.corners[i].owners.corner, 200, 103.5 + 0.004 * (i + 1));
  auto& rl = late.in.corners[2].owners;
  for (auto& x : rl.switches) x.mono_s += 3.4;  // every kept change but the first 32 now after the failure
  for (std::size_t j = 0; j < T::kKeepFirst; ++j) rl.switches[j].mono_s -= 3.4;
  const auto lr = launch::assess_failover(late.in);
  EXPECT_NE(lr.takeover_missing.find("RL ("), std::string::npos) << lr.takeover_missing;
  EXPECT_NE(lr.takeover_missing.find("not kept"), std::string::npos) << lr.takeover_missing;
}

TEST(LaunchOutDir, AStandbyRunsFilesAreOwnAndCleared) {
  namespace fs = std::filesystem;
  const fs::path d = fs::temp_directory_path() / ("bbw_failover_parts_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d / "standby");
  for (const char* f : {"ccu_failover.stats", "corner_FL_failover.stats", "ccu_standby.out", "ccu.stats"}) {
    std::ofstream(d / f) << "x";
  }
  std::ofstream(d / "standby" / "ccu_FL.csv") << "x";
  const auto r = launch::prepare_out_dir(d.string());
  EXPECT_EQ(r.removed.size(), 5u);
  EXPECT_FALSE(fs::exists(d / "standby"));
  // A standby folder holding something bbw did not write is refused, nothing removed.
  fs::create_directories(d / "standby");
  std::ofstream(d / "standby" / "notes.txt") << "mine";
  EXPECT_THROW(launch::prepare_out_dir(d.string()), std::invalid_argument);
  EXPECT_TRUE(fs::exists(d / "standby" / "notes.txt"));
  fs::remove_all(d);
}

}  // namespace

namespace {

// bbw_launch's checks of a standby scenario before anything starts.
TEST(LaunchStandbyChecks, LinkCutIsRefusedAndAHangNeedsAStandby) {
  const std::string dir = std::string(BBW_TEST_SOURCE_DIR) + "/config/scenarios/faults/";
  bbw::launch::Options o;
  o.scenario_file = dir + "ccu_failover_link_cut.yaml";
  try {
    bbw::launch::load_run(o);
    FAIL() << "a link cut must be refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("line 33: a link_cut needs the processes in network namespaces"), std::string::npos)
        << e.what();
  }
  o.scenario_file = dir + "ccu_failover_hang.yaml";
  EXPECT_TRUE(bbw::launch::load_run(o).schedule.standby);
  // The same hang without `standby: true` (the scenario's key removed) and without --standby.
  const auto p = std::filesystem::temp_directory_path() / ("bbw_hang_no_standby_" + std::to_string(::getpid()) + ".yaml");
  {
    std::ifstream in(o.scenario_file);
    std::ofstream out(p);
    std::string line;
    while (std::getline(in, line)) {
      if (line == "standby: true" || line.rfind("processes: ", 0) == 0) continue;
      if (line.rfind("plant: ", 0) == 0) line = "plant: " + std::string(BBW_TEST_SOURCE_DIR) + "/config/plant/ecaliper.yaml";
      out << line << "\n";
    }
  }
  o.scenario_file = p.string();
  try {
    bbw::launch::load_run(o);
    FAIL() << "a hang without a standby must be refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("a CCU hang needs a hot-standby CCU (standby: true or --standby)"), std::string::npos)
        << e.what();
  }
  o.standby = true;
  EXPECT_TRUE(bbw::launch::load_run(o).schedule.standby);
  std::filesystem::remove(p);
}

}  // namespace
