// A hot-standby CCU over the real processes (issue 16, docs/faults.md "Hot-standby CCU"):
// bbw_launch starts bbw_ccu (primary), bbw_ccu_standby and four bbw_corner over Fast DDS on this
// host; the scenario kills or hangs the primary (or both CCUs), and the run's summary.json
// `failover` object (measured at the corners over DDS) is checked against the goals: takeover
// <= 20 ms after the failure, no command gap over 25 ms at the takeover, clamp-force dip <= 0.5
// kN, no safe-state entry; both CCUs lost: every corner in its safe state. Lockstep and realtime.
//
// Realtime runs are started under SCHED_FIFO (chrt -f 10, inherited by every process and thread
// of the run) when the test runs as root: on this 2-core machine, shared with builds (load 6-10),
// a run at nice 0 let even a single-CCU run's corners miss 20 ms of commands (their watchdog fired
// in 4 of 8 corner runs, wake-up jitter up to 58 ms); at nice -10 stalls of 39-150 ms remained
// under the heaviest load; under SCHED_FIFO the jitter was 1-3 ms. A brake controller runs with
// a real-time priority. Without root the runs go at normal priority (and may miss the goals).
//
// Domains 60-65 (one per test). Each run is bounded by the launcher and by this test.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "bbw/runtime/failover_stats.hpp"
#include "failover_starved.hpp"
#include "system_test_support.hpp"

namespace {

using namespace std::chrono_literals;
using namespace bbw::system_test;
namespace fs = std::filesystem;

// The object `key` of summary.json (our writer: one key per line), values unquoted.
std::map<std::string, std::string> object(const std::string& json, const std::string& key) {
  std::map<std::string, std::string> m;
  const auto a = json.find("\"" + key + "\": {");
  if (a == std::string::npos) return m;
  const auto end = json.find('}', a);
  std::istringstream lines(json.substr(a, end - a));
  std::string line;
  std::getline(lines, line);  // "key": {
  while (std::getline(lines, line)) {
    std::string k, v;
    if (member_line(line, k, v)) m[k] = v;
  }
  return m;
}

// The .err file under out_dir of a process that died of one of Fast DDS 2.9's own assertions
// named above, or "".
std::string fastdds_abort(const std::string& out_dir) {
  if (const std::string f = fastdds_pdp_abort(out_dir); !f.empty()) return f;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out_dir, ec)) {
    if (e.path().extension() != ".err") continue;
    const std::string text = slurp(e.path().string());
    if (text.find("RTPSStatisticsMessages.hpp") != std::string::npos && text.find("Assertion") != std::string::npos) {
      return e.path().string();
    }
  }
  return "";
}

// A realtime standby run that the machine, not the CCUs, decided (failover_starved.hpp), from
// the stats under out; "" also when the run has no stats to tell.
std::string ccus_starved(const std::string& out) {
  const std::string primary_file = out + "/ccu_failover.stats", standby_file = out + "/standby/ccu_failover.stats";
  if (!fs::exists(primary_file) || !fs::exists(standby_file)) return "";
  const auto primary = bbw::runtime::load_ccu_failover(primary_file);
  return bbw::system_test::ccus_starved(primary, bbw::runtime::load_ccu_failover(standby_file), primary.failed_mono_s);
}

double num(const std::map<std::string, std::string>& m, const std::string& k) {
  const auto it = m.find(k);
  if (it == m.end() || it->second == "null") {
    ADD_FAILURE() << "failover." << k << " is missing or null";
    return std::nan("");
  }
  return std::stod(it->second);
}

struct StandbyRun {
  ProcessRun launch;
  std::string out;
  std::map<std::string, std::string> failover;
  std::string report() const {
    std::string s = "launcher exit: " + launch.status.describe() + "\n" + launch.out + launch.err + "failover:\n";
    for (const auto& [k, v] : failover) s += "  " + k + " = " + v + "\n";
    return s;
  }
};

StandbyRun launch_standby(const std::string& scenario, const std::string& test, int domain, const std::string& mode,
                          const std::vector<std::string>& extra = {}) {
  const std::string dir = scratch("failover", test);
  std::vector<std::string> argv{bin("bbw_launch"), src("config/scenarios/faults/" + scenario), "--out", dir + "/out", "--mode",
                                 mode, "--domain", std::to_string(domain), "--discovery-timeout", "20", "--no-report"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  if (mode == "realtime") argv = at_realtime_priority(std::move(argv));
  StandbyRun r;
  for (int attempt = 1;; ++attempt) {
    r.launch = run("bbw_launch", argv, dir, 120s);
    // Fast DDS 2.9 aborts now and then inside its own code (assertions left on in Debian's
    // build): the discovery race of docs/faults.md, and, with --secure, a statistics submessage
    // that does not fit the message buffer (RTPSStatisticsMessages.hpp:100, 1 of 3 secure runs
    // once). On these, and only on these, the run is repeated (at most twice), with a note.
    const std::string abort_file = r.launch.status.ok() ? "" : fastdds_abort(dir + "/out");
    // In realtime the goals judge the CCUs' reaction, not the machine's: a run the machine decided
    // (`ccus_starved`: the standby starved across the takeover, or both CCUs at once) is repeated
    // too (at most twice), with a note. Seen on 2026-11-26 in the system set at -j2: a 30 ms
    // takeover with the standby stalled from 6 ms before to 32 ms after the primary's kill; the
    // corners' safe state at 0.84 s and 1.27 s, long before any failure, with both CCUs stalled.
    const std::string starved = mode == "realtime" && abort_file.empty() ? ccus_starved(dir + "/out") : "";
    if ((abort_file.empty() && starved.empty()) || attempt == 3) break;
    if (!abort_file.empty()) {
      std::cout << "[ NOTE     ] run " << attempt << " of " << scenario << " hit a Fast DDS 2.9 assertion, in " << abort_file
                << "; running it again" << std::endl;
    } else {
      std::cout << "[ NOTE     ] run " << attempt << " of " << scenario << " not judged: " << starved << "; running it again"
                << std::endl;
    }
  }
  r.out = dir + "/out";
  r.failover = object(slurp(r.out + "/summary.json"), "failover");
  // The measured figures, for docs/faults.md.
  std::cout << "[ MEASURED ] " << scenario << " " << mode << ":";
  for (const char* k : {"takeover_ms", "takeover_wall_ms", "takeover_gap_ms", "max_command_gap_ms", "max_command_gap_wall_ms",
                        "max_force_dip_kN", "safe_state_entered", "safe_state_s", "switches_before_failure",
                        "switches_back_to_primary", "primary_outages", "standby_outages", "primary_stalls", "standby_stalls", "owners_at_end"}) {
    const auto it = r.failover.find(k);
    std::cout << " " << k << "=" << (it == r.failover.end() ? "?" : it->second);
  }
  std::cout << std::endl;
  return r;
}

// What every single failure (kill, hang) must give: the standby took over every corner within
// the goals, and no corner entered its safe state.
void expect_clean_takeover(const StandbyRun& r, const std::string& failure, bool lockstep) {
  const auto& f = r.failover;
  EXPECT_EQ(f.count("failure") ? f.at("failure") : "", failure) << r.report();
  EXPECT_DOUBLE_EQ(num(f, "failed_s"), 3.5) << r.report();
  EXPECT_EQ(f.count("takeover_missing") ? f.at("takeover_missing") : "?", "") << r.report();
  const double takeover_ms = num(f, "takeover_ms");
  if (lockstep) {
    // Simulated time stands still while the corners wait: the standby's first command is for
    // the period the primary did not grant (3.5 s), at most one period later.
    EXPECT_GE(takeover_ms, 0.0) << r.report();
    EXPECT_LE(takeover_ms, 5.0 + 1e-6) << r.report();
    EXPECT_NEAR(num(f, "max_command_gap_ms"), 5.0, 1e-6) << r.report();  // one period, always
  } else {
    EXPECT_GT(takeover_ms, 0.0) << r.report();
    EXPECT_LE(takeover_ms, 20.0) << "goal: takeover <= 20 ms after the failure\n" << r.report();
    EXPECT_LE(num(f, "takeover_gap_ms"), 25.0) << "goal: no command gap over 25 ms\n" << r.report();
  }
  EXPECT_LE(num(f, "max_force_dip_kN"), 0.5) << "goal: clamp-force dip <= 0.5 kN\n" << r.report();
  EXPECT_EQ(f.count("safe_state_entered") ? f.at("safe_state_entered") : "", "false") << r.report();
}

// The standby received every measurement sample (it was warm: its calibrators were fed the same
// samples as the primary's), per its ccu.stats, and every corner published its samples.
void expect_standby_fed(const StandbyRun& r) {
  const std::string text = slurp(r.out + "/summary.json");
  for (const auto& c : objects(text, "corners")) {
    EXPECT_EQ(c.at("samples_received"), c.at("samples_published")) << c.at("corner") << "\n" << r.report();
    EXPECT_EQ(c.at("sample_gaps"), "0") << c.at("corner") << "\n" << r.report();
  }
}

// Lockstep: the two CCUs are one deterministic function of the same blocks, so the primary's logs
// up to its failure are a prefix of the standby's, byte for byte (the standby was as good as the
// primary at every moment).
void expect_identical_prefix(const StandbyRun& r) {
  for (const std::string c : {"FL", "FR", "RL", "RR"}) {
    const std::string primary = slurp(r.out + "/ccu_" + c + ".csv");
    const std::string standby = slurp(r.out + "/standby/ccu_" + c + ".csv");
    ASSERT_GT(primary.size(), 1000u) << c;
    EXPECT_EQ(standby.compare(0, primary.size(), primary), 0) << "ccu_" << c << ".csv of the primary is not a prefix of the standby's";
  }
}

// The hand-back rule (docs/faults.md "Hand-back"): the CCU with fewer outages leads, the primary
// at equal counts. At the end every corner obeys that CCU.
void expect_owner_by_outages(const StandbyRun& r) {
  const auto& f = r.failover;
  const double p = num(f, "primary_outages"), s = num(f, "standby_outages");
  const std::string leader = p <= s ? "primary" : "standby";
  EXPECT_EQ(f.count("owners_at_end") ? f.at("owners_at_end") : "", leader + "," + leader + "," + leader + "," + leader)
      << "outages: primary " << p << ", standby " << s << "\n" << r.report();
}

TEST(SystemFailover, KilledPrimaryLockstep) {  // domain 60
  const StandbyRun r = launch_standby("ccu_failover_kill.yaml", "kill_lockstep", 60, "lockstep");
  ASSERT_TRUE(r.launch.status.ok()) << r.report();
  expect_clean_takeover(r, "kill", true);
  EXPECT_EQ(num(r.failover, "switches_back_to_primary"), 0.0) << r.report();
  expect_standby_fed(r);
  expect_identical_prefix(r);
}

TEST(SystemFailover, KilledPrimaryRealtime) {  // domain 61
  const StandbyRun r = launch_standby("ccu_failover_kill.yaml", "kill_realtime", 61, "realtime");
  ASSERT_TRUE(r.launch.status.ok()) << r.report();
  expect_clean_takeover(r, "kill", false);
  EXPECT_EQ(num(r.failover, "switches_back_to_primary"), 0.0) << r.report();
  expect_standby_fed(r);
}

TEST(SystemFailover, HungPrimaryLockstepLeavesTheRun) {  // domain 62
  const StandbyRun r = launch_standby("ccu_failover_hang.yaml", "hang_lockstep", 62, "lockstep");
  ASSERT_TRUE(r.launch.status.ok()) << r.report();
  expect_clean_takeover(r, "hang", true);
  // Continued 0.5 s later it lowers its strength and leaves (it cannot rejoin the lock step).
  EXPECT_EQ(r.failover.at("primary_demote_reason"), "resumed after a stop") << r.report();
  EXPECT_NE(slurp(r.out + "/ccu.out").find("leaves the run"), std::string::npos) << r.report();
  EXPECT_EQ(num(r.failover, "switches_back_to_primary"), 0.0) << r.report();
  expect_identical_prefix(r);
}

TEST(SystemFailover, HungPrimaryRealtimeIsNotHandedBack) {  // domain 63
  const StandbyRun r = launch_standby("ccu_failover_hang.yaml", "hang_realtime", 63, "realtime");
  ASSERT_TRUE(r.launch.status.ok()) << r.report();
  expect_clean_takeover(r, "hang", false);
  // Continued 0.5 s later, the primary counts the hang as an outage and runs on below the standby.
  const auto primary = bbw::runtime::load_ccu_failover(r.out + "/ccu_failover.stats");
  EXPECT_GE(primary.outages, 1u) << r.report();
  EXPECT_GT(primary.resumed_mono_s, primary.failed_mono_s + 0.4) << r.report();
  expect_owner_by_outages(r);
}

TEST(SystemFailover, BothCcusLostLockstepGivesTheSafeState) {  // domain 64
  const StandbyRun r = launch_standby("ccu_failover_both_lost.yaml", "both_lockstep", 64, "lockstep");
  ASSERT_TRUE(r.launch.status.ok()) << r.report();
  const auto& f = r.failover;
  EXPECT_LE(num(f, "takeover_ms"), 5.0 + 1e-6) << r.report();
  EXPECT_DOUBLE_EQ(num(f, "standby_failed_s"), 4.0) << r.report();
  EXPECT_EQ(f.at("safe_state_entered"), "true") << r.report();
  // The watchdog: no command for 20 ms after the standby's last one (for 3.995 s).
  EXPECT_NEAR(num(f, "safe_state_s"), 4.016, 0.002) << r.report();
  for (const auto& c : objects(slurp(r.out + "/summary.json"), "corners")) {
    EXPECT_NEAR(std::stod(c.at("ccu_lost_detected_s")), 4.016, 0.002) << c.at("corner");
  }
}

TEST(SystemFailover, BothCcusLostRealtimeGivesTheSafeState) {  // domain 65
  const StandbyRun r = launch_standby("ccu_failover_both_lost.yaml", "both_realtime", 65, "realtime");
  ASSERT_TRUE(r.launch.status.ok()) << r.report();
  const auto& f = r.failover;
  EXPECT_LE(num(f, "takeover_ms"), 20.0) << r.report();
  EXPECT_DOUBLE_EQ(num(f, "standby_failed_s"), 4.0) << r.report();
  EXPECT_EQ(f.at("safe_state_entered"), "true") << r.report();
  for (const auto& c : objects(slurp(r.out + "/summary.json"), "corners")) {
    const double lost = std::stod(c.at("ccu_lost_detected_s"));
    EXPECT_GE(lost, 4.0) << c.at("corner") << ": safe state before the standby was lost\n" << r.report();
    EXPECT_LE(lost, 4.06) << c.at("corner") << "\n" << r.report();
  }
}

// With --secure the standby is its own DDS Security identity (bbw_ccu_standby) with the CCU's
// rights: its commands pass the corners' access control (it takes over), and only the two CCU
// identities may publish commands at all.
TEST(SystemFailover, SecureStandbyHasItsOwnIdentity) {  // domain 69
  const std::string keys = scratch("failover", "keys");
  const StandbyRun r = launch_standby("ccu_failover_kill.yaml", "secure", 69, "lockstep", {"--secure", "--keys", keys});
  ASSERT_TRUE(r.launch.status.ok()) << r.report();
  expect_clean_takeover(r, "kill", true);
  EXPECT_EQ(r.failover.at("owners_at_end"), "standby,standby,standby,standby") << r.report();
  const std::string standby = slurp(keys + "/ccu_standby/permissions.xml");
  EXPECT_NE(standby.find("CN=bbw_ccu_standby"), std::string::npos) << standby;
  for (const std::string id : {"ccu", "ccu_standby", "fl", "fr", "rl", "rr"}) {
    const std::string perm = slurp(keys + "/" + id + "/permissions.xml");
    const auto publish = perm.find("<publish>");
    ASSERT_NE(publish, std::string::npos) << id;
    const bool commands = perm.substr(publish, perm.find("</publish>") - publish).find("bbw/ClampCommand") != std::string::npos;
    EXPECT_EQ(commands, id == "ccu" || id == "ccu_standby") << id << " may publish commands: " << commands;
  }
}

}  // namespace
