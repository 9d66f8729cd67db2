// The whole system under DDS Security (issue 7, docs/security.md) and hostile DDS input:
// bbw_launch --secure with real bbw_ccu / bbw_corner processes and bbw_intruder next to them.
// Domains 221-226, one per test (the flood test's retries also 227 and 229-232). Every run and every intruder is bounded (launcher wall-time
// bound, intruder --duration-s, waits with deadlines); nothing sleeps.
#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <chrono>
#include <cmath>
#include <iostream>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bbw/runtime/child.hpp"
#include "system_test_support.hpp"
#include "bbw/runtime/stats_file.hpp"

namespace {

using namespace std::chrono_literals;
using bbw::system_test::bin;
using bbw::system_test::fastdds_pdp_abort;
using bbw::system_test::Launch;
using bbw::system_test::ProcessRun;
using bbw::system_test::slurp;
using bbw::system_test::src;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;


const char* kCorners[] = {"FL", "FR", "RL", "RR"};
constexpr double kIntruderForce = 77.7;  // kN: no scenario commands it, so it is easy to spot


std::string scratch(const std::string& test) { return bbw::system_test::scratch("secure", test); }

// BBW_DDS_LOG=warning: a failed handshake or discovery leaves Fast DDS's warnings in the
// children's .err files (nothing is printed when all goes well).
ProcessRun run(const std::string& name, const std::vector<std::string>& argv, const std::string& dir,
               std::chrono::seconds limit) {
  return bbw::system_test::run(name, argv, dir, limit, {"BBW_DDS_LOG=warning"});
}

// realtime_priority: the run under SCHED_FIFO 10 (chrt, inherited by every process and thread
// of the run) when the test runs as root, as a brake controller runs and as the failover tests
// run theirs (test_failover_runs.cpp says why): a wall-clock criterion then judges the run, not
// the rest of the machine's load.
std::vector<std::string> launch_argv(const std::string& dir, int domain, const std::string& mode, bool secure,
                                     bool realtime_priority = false) {
  std::vector<std::string> a{bin("bbw_launch"), src("tests/system/data/short_rig.yaml"), "--out", dir + "/out",
                             "--mode", mode, "--domain", std::to_string(domain), "--discovery-timeout", "20",
                             "--no-report"};
  if (secure) a.insert(a.end(), {"--secure", "--keys", dir + "/keys"});
  return realtime_priority ? bbw::system_test::at_realtime_priority(std::move(a)) : a;
}

ProcessRun launch(const std::string& dir, int domain, const std::string& mode, bool secure, bool realtime_priority = false) {
  return run("bbw_launch", launch_argv(dir, domain, mode, secure, realtime_priority), dir, 150s);
}

// Lines in a file so far (0 when it does not exist).
[[maybe_unused]] std::size_t lines_in(const std::string& file) {
  std::ifstream f(file);
  std::size_t n = 0;
  std::string line;
  while (std::getline(f, line)) ++n;
  return n;
}

// A launcher started now; intruders that know its run id (issue 17: runs have their own DDS
// partitions, so an intruder must know the run id to reach it) start once it is printed.
[[maybe_unused]] std::unique_ptr<Launch> start_launch(const std::string& dir, int domain, const std::string& mode,
                                                      bool secure, bool realtime_priority = false) {
  return std::make_unique<Launch>(dir, "bbw_launch", launch_argv(dir, domain, mode, secure, realtime_priority),
                                  std::vector<std::string>{"BBW_DDS_LOG=warning"});
}

// Waits (bounded) for a launcher started by start_launch(), as launch() would have run it.
[[maybe_unused]] ProcessRun finish_launch(Launch& l) {
  const bbw::runtime::ExitStatus st = l.wait(150s);
  return {st, l.out(), l.err(), ""};
}

double stat(const std::string& file, const std::string& key) {
  return bbw::runtime::stat_number(bbw::runtime::read_stats(file), key, file);
}

// A CSV file as rows of numbers by column name ("nan", "inf" parse as such).
struct Table {
  std::map<std::string, std::size_t> col;
  std::vector<std::vector<double>> rows;
  double at(std::size_t r, const std::string& name) const { return rows[r][col.at(name)]; }
};

Table read_table(const std::string& file) {
  Table t;
  std::ifstream f(file);
  std::string line, cell;
  if (!std::getline(f, line)) return t;
  std::stringstream h(line);
  for (std::size_t i = 0; std::getline(h, cell, ','); ++i) t.col[cell] = i;
  while (std::getline(f, line)) {
    std::vector<double> row;
    std::stringstream ls(line);
    while (std::getline(ls, cell, ',')) row.push_back(std::strtod(cell.c_str(), nullptr));
    if (row.size() == t.col.size()) t.rows.push_back(std::move(row));
  }
  return t;
}

// Periods in which a corner applied the intruder's force.
[[maybe_unused]] std::size_t periods_with_intruder_force(const std::string& out, const std::string& corner) {
  const Table t = read_table(out + "/corner_" + corner + "_periods.csv");
  std::size_t n = 0;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    if (std::fabs(t.at(r, "applied_kN") - kIntruderForce) < 1e-6) ++n;
  }
  return n;
}

// One bbw_intruder process, started now, reporting one JSON line at its end.
class Intruder {
 public:
  // niced: at the lowest CPU priority (nice 19), for a flooder that stands for another ECU.
  Intruder(const std::string& dir, const std::string& name, std::vector<std::string> args, bool niced = false)
      : dir_(dir), name_(name) {
    fs::remove(ready_file());
    args.insert(args.end(), {"--ready-file", ready_file()});
    args.insert(args.begin(), bin("bbw_intruder"));
    if (niced) args.insert(args.begin(), {"/usr/bin/nice", "-n", "19"});
    child_ = std::make_unique<bbw::runtime::Child>(name, args, dir + "/" + name + ".stdout", dir + "/" + name + ".stderr");
  }
  bool running() { return !child_->poll().has_value(); }
  // Its attempt is under way: a first command to every corner written, or it was refused.
  bool ready() const { return fs::exists(ready_file()); }
  // Stops it (SIGTERM ends its attempt) and waits (bounded) for the end; its exit status.
  bbw::runtime::ExitStatus stop(std::chrono::seconds limit) {
    if (running()) child_->send_signal(SIGTERM);
    auto st = child_->wait_until(Clock::now() + limit);
    if (!st) st = child_->stop(2000ms);
    return *st;
  }
  // stop(), expecting a clean end; the JSON line it printed.
  std::string finish(std::chrono::seconds limit) {
    const bbw::runtime::ExitStatus st = stop(limit);
    EXPECT_TRUE(st.ok()) << name_ << ": " << st.describe() << "\n" << slurp(dir_ + "/" + name_ + ".stderr");
    return slurp(dir_ + "/" + name_ + ".stdout");
  }

 private:
  std::string ready_file() const { return dir_ + "/" + name_ + ".ready"; }
  std::string dir_, name_;
  std::unique_ptr<bbw::runtime::Child> child_;
};

// "key":number from the intruder's JSON line (-1 when absent).
[[maybe_unused]] double json_number(const std::string& json, const std::string& key) {
  const auto p = json.find("\"" + key + "\":");
  if (p == std::string::npos) return -1.0;
  return std::strtod(json.c_str() + p + key.size() + 3, nullptr);
}
[[maybe_unused]] bool json_true(const std::string& json, const std::string& key) {
  return json.find("\"" + key + "\":true") != std::string::npos;
}

[[maybe_unused]] void make_keys(const std::string& dir) {
  const ProcessRun k = run("bbw-keys", {src("scripts/bbw-keys.sh"), dir + "/keys"}, dir, 120s);
  ASSERT_TRUE(k.status.ok()) << k.status.describe() << "\n" << k.err;
}

// The launcher checks as the system tests do: every sample and command arrived, nothing else.
[[maybe_unused]] void expect_clean_lockstep_run(const std::string& out) {
  const std::string ccu = out + "/ccu.stats";
  EXPECT_EQ(stat(ccu, "periods_done"), 800.0);
  EXPECT_EQ(stat(ccu, "foreign_corner_samples"), 0.0);
  EXPECT_EQ(stat(ccu, "unknown_corner_blocks"), 0.0);
  for (const char* c : kCorners) {
    const std::string p = std::string(c) + ".";
    const std::string cs = out + "/corner_" + c + ".stats";
    EXPECT_EQ(stat(ccu, p + "samples_received"), 4000.0) << c;
    EXPECT_EQ(stat(ccu, p + "block_gaps"), 0.0) << c;
    EXPECT_EQ(stat(ccu, p + "sample_gaps"), 0.0) << c;
    EXPECT_EQ(stat(ccu, p + "samples_invalid"), 0.0) << c;
    EXPECT_EQ(stat(cs, "commands_applied"), 800.0) << c;
    EXPECT_EQ(stat(cs, "command_seq_gaps"), 0.0) << c;
  }
}

#ifndef BBW_FLOOD_TEST
// Domains 221 (without security) and 222 (with): the short lockstep scenario gives the same
// result byte for byte; the launcher creates the missing keys itself.
TEST(SystemSecure, LockstepRunEqualsTheRunWithoutSecurity) {
  const std::string plain = scratch("plain");
  const std::string secure = scratch("secure");
  const ProcessRun a = launch(plain, 221, "lockstep", false);
  ASSERT_TRUE(a.status.ok()) << a.status.describe() << "\n" << a.out << a.err;
  ASSERT_FALSE(fs::exists(secure + "/keys"));
  const ProcessRun b = launch(secure, 222, "lockstep", true);
  ASSERT_TRUE(b.status.ok()) << b.status.describe() << "\n" << b.out << b.err;
  EXPECT_NE(b.out.find("creating DDS Security keys"), std::string::npos) << b.out;
  EXPECT_TRUE(fs::exists(secure + "/keys/ccu/permissions.p7s"));
  EXPECT_NE(slurp(secure + "/out/summary.json").find("\"secure\": true"), std::string::npos);
  EXPECT_NE(slurp(plain + "/out/summary.json").find("\"secure\": false"), std::string::npos);
  // The children really ran with security (their command lines carry the keys directory).
  expect_clean_lockstep_run(secure + "/out");
  for (const char* c : kCorners) {
    const std::string la = slurp(plain + "/out/ccu_" + std::string(c) + ".csv");
    const std::string lb = slurp(secure + "/out/ccu_" + std::string(c) + ".csv");
    ASSERT_GT(la.size(), 100000u) << c;
    EXPECT_TRUE(la == lb) << "corner " << c << ": the CCU's log with security differs from the one without";
  }
  fs::remove_all(plain);
  fs::remove_all(secure);
}

// Domain 223: while a secure lockstep run goes on from start to end, three intruders try to
// command every corner with 77.7 kN: unsecured, with a rogue CA's certificate, and as a
// certified corner (FL) whose permissions grant no commands. None matches; no corner ever
// applies the force; the run is as clean as without them.
TEST(SystemSecure, IntrudersNeverCommandACornerOfASecureRun) {
  const std::string dir = scratch("intruders");
  make_keys(dir);
  const std::string keys = dir + "/keys";
  const std::vector<std::string> common{"--keys", keys, "--domain", "223", "--duration-s", "60", "--force-kN", "77.7"};
  auto args = [&](std::vector<std::string> a) {
    a.insert(a.end(), common.begin(), common.end());
    return a;
  };
  // The intruders know the run id (as they could read it in discovery): only security stops them.
  // They join once the run is under way (the CCU logs samples): joining while the five secure
  // participants still shake hands made Fast DDS 2.9's handshake race (below) leave three
  // corners unauthenticated for the whole 20 s discovery deadline (1 of 2 full-suite runs).
  // The intruders must be writing before the run ends, or the test proves nothing: a clean-clone
  // CI run's rogue intruder had written nothing when the 3 s lockstep run ended. A run that ended
  // before all three were under way (each says so in its --ready-file) is not judged and is run
  // again, at most three times.
  for (int attempt = 1;; ++attempt) {
    fs::remove_all(dir + "/out");
    auto l = start_launch(dir, 223, "lockstep", true);
    const std::string run_id = l->run_id();
    ASSERT_EQ(run_id.size(), 16u) << l->out() << l->err();
    const auto underway = Clock::now() + 60s;
    while (Clock::now() < underway && lines_in(dir + "/out/ccu_FL.csv") < 50 && !l->ended_within(20ms)) {
    }
    ASSERT_GE(lines_in(dir + "/out/ccu_FL.csv"), 50u) << "the run never got under way\n" << l->out() << l->err();
    Intruder none(dir, "intruder_none", args({"--as", "none", "--run-id", run_id}));
    Intruder rogue(dir, "intruder_rogue", args({"--as", "rogue", "--run-id", run_id}));
    Intruder corner(dir, "intruder_corner", args({"--as", "corner", "--corner", "FL", "--run-id", run_id}));
    bool run_ended = false;
    const auto ready_by = Clock::now() + 60s;
    while (Clock::now() < ready_by && !(none.ready() && rogue.ready() && corner.ready())) {
      if (l->ended_within(20ms)) {
        run_ended = true;
        break;
      }
    }
    const bool all_ready = none.ready() && rogue.ready() && corner.ready();
    const ProcessRun r = finish_launch(*l);
    if (!all_ready && attempt < 3) {
      std::cout << "[ NOTE     ] attempt " << attempt << ": the run " << (run_ended ? "ended" : "went on for 60 s")
                << " before every intruder was under way (none " << none.ready() << ", rogue " << rogue.ready()
                << ", corner " << corner.ready() << "); running it again" << std::endl;
      none.stop(20s), rogue.stop(20s), corner.stop(20s);
      continue;
    }
    EXPECT_TRUE(all_ready) << "the intruders were not under way before the run ended (none " << none.ready() << ", rogue "
                           << rogue.ready() << ", corner " << corner.ready() << ")";
    // The intruders were there until the end of the run.
    EXPECT_TRUE(none.running() && rogue.running()) << "the run outlasted the intruders: make --duration-s longer";
    ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
    expect_clean_lockstep_run(dir + "/out");
    for (const char* c : kCorners) {
      EXPECT_EQ(periods_with_intruder_force(dir + "/out", c), 0u) << "corner " << c << " applied the intruder's force";
    }
    const std::string jn = none.finish(20s), jr = rogue.finish(20s), jc = corner.finish(20s);
    for (const std::string* j : {&jn, &jr}) {
      EXPECT_TRUE(json_true(*j, "participant") && json_true(*j, "writer")) << *j;
      EXPECT_GE(json_number(*j, "written"), 4.0) << *j;  // at least one command to every corner, during the run
      EXPECT_EQ(json_number(*j, "max_matched"), 0.0) << *j;
    }
    EXPECT_TRUE(json_true(jc, "participant")) << jc;
    EXPECT_FALSE(json_true(jc, "writer")) << "access control let corner FL write commands: " << jc;
    EXPECT_EQ(json_number(jc, "max_matched"), 0.0) << jc;
    break;
  }
  fs::remove_all(dir);
}

// Domain 224: without security, an intruder that does not know the run id (it writes
// partition-less commands, as before issue 17) matches no corner: each run reads commands only
// in its own partition run_<id>. The positive control, an unsecured intruder that does know the
// run id and reaches every corner (which then refuse it), is SystemGate in test_run_safety.cpp.
TEST(SystemSecure, WithoutSecurityAnIntruderThatDoesNotKnowTheRunReachesNoCorner) {
  const std::string dir = scratch("unprotected");
  Intruder none(dir, "intruder_none", {"--as", "none", "--domain", "224", "--duration-s", "60", "--force-kN", "77.7"});
  const ProcessRun r = launch(dir, 224, "realtime", false);
  EXPECT_TRUE(none.running());
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
  std::size_t applied = 0;
  for (const char* c : kCorners) applied += periods_with_intruder_force(dir + "/out", c);
  EXPECT_EQ(applied, 0u) << "an intruder without the run id commanded a corner";
  const std::string j = none.finish(20s);
  EXPECT_GT(json_number(j, "written"), 400.0) << j;
  EXPECT_EQ(json_number(j, "max_matched"), 0.0) << j;
  fs::remove_all(dir);
}

// Domain 225: a publisher as corner FL (in FL's partition, unsecured: the CCU treats it as a
// compromised certified FL) sends malformed blocks through a realtime run: NaN and infinite
// values, values out of range, a sequence going backwards, FR's corner id, corner id 7. The
// CCU drops the foreign and unknown ids (counted) and never uses a bad sample as valid; the
// other corners are untouched.
TEST(SystemHostileInput, MalformedMeasurementsAreRejectedAndCounted) {
  const std::string dir = scratch("hostile");
  auto l = start_launch(dir, 225, "realtime", false);
  const std::string run_id = l->run_id();
  ASSERT_EQ(run_id.size(), 16u) << l->out() << l->err();
  Intruder hostile(dir, "intruder_hostile", {"--as", "none", "--corner", "FL", "--measurements", "hostile", "--domain", "225",
                                             "--duration-s", "60", "--run-id", run_id});
  const ProcessRun r = finish_launch(*l);
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
  const std::string j = hostile.finish(20s);
  ASSERT_GE(json_number(j, "max_matched"), 1.0) << j;
  const std::string out = dir + "/out", ccu = out + "/ccu.stats";
  EXPECT_GT(stat(ccu, "FL.foreign_blocks"), 0.0);
  EXPECT_GT(stat(ccu, "unknown_corner_blocks"), 0.0);
  EXPECT_LE(stat(ccu, "FL.foreign_blocks"), json_number(j, "foreign") + json_number(j, "unknown"));
  EXPECT_GT(stat(ccu, "FL.samples_invalid"), 0.0);
  // FR's id in FL's partition never reached FR; the other corners saw exactly their own data.
  for (const char* c : {"FR", "RL", "RR"}) {
    const std::string p = std::string(c) + ".";
    EXPECT_EQ(stat(ccu, p + "foreign_blocks"), 0.0) << c;
    EXPECT_EQ(stat(ccu, p + "samples_invalid"), 0.0) << c;
    EXPECT_EQ(stat(ccu, p + "samples_received"), stat(out + "/corner_" + c + ".stats", "samples_published")) << c;
  }
  // Every sample the CCU logged for FL: a bad value is never valid; valid samples move forward.
  const Table t = read_table(out + "/ccu_FL.csv");
  ASSERT_GT(t.rows.size(), 100u);
  std::size_t bad = 0, bad_accepted = 0, backwards_accepted = 0, load_cell_ignored = 0;
  double last_seq = -1.0, last_time = -1e300;
  std::string backwards;  // the first few, with the accepted sample before each
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const double x = t.at(i, "position_rev"), f = t.at(i, "force_internal_kN");
    const bool bad_rest = !std::isfinite(x) || x > 10.0 || x < -1.0;
    const bool bad_load_cell = std::isinf(f) || f > 80.0 || f < -10.0;
    const bool accepted = t.at(i, "accepted") == 1.0;  // let through by the CCU's sample guard
    // Once the CCU has named FL's load cell faulty, a load-cell value out of range is no value
    // (guard.diagnosed_load_cell_out_of_range_is_absent): the rest of the sample may be kept, and
    // the estimate then comes from the curve (source 2) or none (0), never from that load cell.
    const double source = t.at(i, "source");
    const bool load_cell_unused = source == 0.0 || source == 2.0;
    if (bad_rest || bad_load_cell) ++bad;
    if (accepted && (bad_rest || (bad_load_cell && !load_cell_unused))) ++bad_accepted;
    if (accepted && !bad_rest && bad_load_cell && load_cell_unused) ++load_cell_ignored;
    if (accepted) {
      if (!(t.at(i, "seq") > last_seq) || !(t.at(i, "time_s") > last_time)) {
        if (++backwards_accepted <= 3) {
          backwards += "  row " + std::to_string(i) + ": seq " + std::to_string(t.at(i, "seq")) + " time " +
                       std::to_string(t.at(i, "time_s")) + " after seq " + std::to_string(last_seq) + " time " +
                       std::to_string(last_time) + "\n";
        }
      }
      last_seq = t.at(i, "seq");
      last_time = t.at(i, "time_s");
    }
  }
  EXPECT_GT(bad, 0u) << "no malformed sample reached the CCU: the test proves nothing";
  EXPECT_EQ(bad_accepted, 0u) << "malformed samples were accepted";
  EXPECT_EQ(static_cast<double>(load_cell_ignored), stat(ccu, "FL.load_cell_ignored"));
  EXPECT_EQ(backwards_accepted, 0u) << "an accepted sample went backwards in sequence or time:\n"
                                    << backwards << "FL rejoins " << stat(ccu, "FL.rejoins") << "\n" << r.err;
  fs::remove_all(dir);
}

#else  // BBW_FLOOD_TEST
// Built as its own executable test_flood_run (RUN_SERIAL): its criterion is wall-clock timing,
// so it does not share the 2 cores with the other system tests.
// Domains 226, 227, 229-232 (one per run): a publisher as corner FL floods the CCU with plausible measurement blocks at 20
// times a corner's rate for the whole realtime run. Criterion (docs/security.md, "Flooding"):
// the other corners' commands are never late beyond their 20 ms deadline (no command deadline
// missed on FR, RL, RR) and the CCU receives every one of their blocks in order, while it did
// receive at least 10 times FL's normal number of blocks.
TEST(SystemHostileInput, AFloodingCornerDoesNotDelayTheOthersCommands) {
  // The run's processes run under SCHED_FIFO 10 as root (launch_argv): at normal priority the
  // test failed once while a sanitizer build ran beside it (every judged flooded run had a late
  // command, the one control run after them none: the build's load, not the flood, decided).
  // The flooder stands for another ECU on the network: at normal priority beside a run under
  // SCHED_FIFO (it cannot take the run's CPU then; niced to 19, six busy loops starved it in 18
  // of 18 runs and nothing could be judged), and at nice 19 beside a run at normal priority
  // (without root), where it would otherwise take the CPU the corner processes need (CPU
  // exhaustion of the CCU's host is outside the threat model, docs/security.md). Timing on this shared VM is
  // noisy even without a flood (command deadline misses in 1 of 8 plain realtime runs, jitter
  // up to 22 ms, and such stalls come in bursts), so the deadline criterion is judged over up to
  // 6 runs: it holds when one run has none; the work bound is checked in every judged run.
  // A run is not judged (and says why) when it carried no full flood: the flooder or a process
  // died of the Fast DDS 2.9 discovery assertion (docs/faults.md), or the niced flooder was
  // starved of CPU by other load and sent under 10x. Each run has its own domain, so a run never
  // meets the participants of the one before.
  constexpr int kAttempts = 6;
  const int domains[kAttempts] = {226, 227, 229, 230, 231, 232};
  const bool run_at_realtime_priority = bbw::system_test::realtime_priority_available();
  bool deadlines_held = false;
  int judged = 0;
  for (int attempt = 1; attempt <= kAttempts && !deadlines_held; ++attempt) {
    const std::string dir = scratch("flood_" + std::to_string(attempt));
    const std::string domain = std::to_string(domains[attempt - 1]);
    auto l = start_launch(dir, domains[attempt - 1], "realtime", false, /*realtime_priority=*/true);
    const std::string run_id = l->run_id();
    ASSERT_EQ(run_id.size(), 16u) << l->out() << l->err();
    Intruder flood(dir, "intruder_flood", {"--as", "none", "--corner", "FL", "--measurements", "flood", "--rate-x", "20",
                                           "--domain", domain, "--duration-s", "60", "--run-id", run_id},
                   /*niced=*/!run_at_realtime_priority);
    const ProcessRun r = finish_launch(*l);
    const bool flood_lasted = flood.running();
    const bbw::runtime::ExitStatus flood_status = flood.stop(20s);
    const std::string out = dir + "/out", ccu = out + "/ccu.stats";
    const std::string aborted = !flood_lasted && slurp(dir + "/intruder_flood.stderr").find("PDP.cpp") != std::string::npos
                                    ? dir + "/intruder_flood.stderr"
                                    : (r.status.ok() ? "" : fastdds_pdp_abort(out));
    if (!aborted.empty()) {
      std::cout << "run " << attempt << " not judged: the Fast DDS 2.9 discovery assertion in " << aborted << "\n";
      fs::remove_all(dir);
      continue;
    }
    ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
    ASSERT_TRUE(flood_lasted) << "the flood ended before the run: " << flood_status.describe() << "\n"
                              << slurp(dir + "/intruder_flood.stderr");
    const double fl_blocks = stat(ccu, "FL.blocks_received") + stat(ccu, "FL.blocks_over_rate");
    if (fl_blocks < 10.0 * 800.0) {
      std::cout << "run " << attempt << " not judged: only " << fl_blocks
                << " FL blocks reached the CCU (under 10x: the niced flooder was starved of CPU)\n";
      fs::remove_all(dir);
      continue;
    }
    ++judged;
    // The CCU processed FL's blocks only up to its budget (2 per period, burst 40) and dropped
    // the rest unread: its work per period stayed bounded.
    EXPECT_GT(stat(ccu, "FL.blocks_over_rate"), 0.0);
    EXPECT_LE(stat(ccu, "FL.blocks_received"), 2.0 * 800.0 + 40.0);
    double misses = 0.0;
    for (const char* c : {"FR", "RL", "RR"}) {
      const std::string p = std::string(c) + ".";
      const std::string cs = out + "/corner_" + c + ".stats";
      misses += stat(cs, "command_deadlines_missed");
      EXPECT_EQ(stat(ccu, p + "blocks_received"), 800.0) << c;
      EXPECT_EQ(stat(ccu, p + "block_gaps"), 0.0) << c;
      std::cout << "run " << attempt << ", " << c << ": command deadline misses " << stat(cs, "command_deadlines_missed")
                << ", CCU measurement deadline misses " << stat(ccu, p + "deadlines_missed") << ", max jitter "
                << stat(cs, "max_jitter_s") * 1e3 << " ms, overruns " << stat(cs, "overruns") << "\n";
    }
    deadlines_held = misses == 0.0;
    fs::remove_all(dir);
  }
  if (deadlines_held) return;
  if (judged == 0) {
    GTEST_SKIP() << "none of " << kAttempts << " runs carried a full flood (see the lines above): the criterion "
                 << "could not be judged on this machine now";
  }
  // Every judged flooded run missed. Judge whether the flood made the difference: the same run
  // without any flood. If it misses too, this machine cannot hold the 20 ms deadline right now
  // and the criterion cannot be judged (the bounded-work checks were asserted in every run).
  const std::string dir = scratch("flood_control");
  const ProcessRun r = launch(dir, 226, "realtime", false, /*realtime_priority=*/true);
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
  double control_misses = 0.0;
  for (const char* c : {"FR", "RL", "RR"}) {
    control_misses += stat(dir + "/out/corner_" + std::string(c) + ".stats", "command_deadlines_missed");
  }
  fs::remove_all(dir);
  if (control_misses > 0.0) {
    GTEST_SKIP() << "each of " << judged << " judged flooded runs had a late command, and so did a run without "
                 << "any flood (" << control_misses << " misses on FR, RL, RR): the machine misses deadlines by "
                 << "itself now, so the flooding criterion cannot be judged on it";
  }
  ADD_FAILURE() << "in each of " << judged << " judged flooded runs a command of FR, RL or RR was late, while a "
                << "run without the flood kept every deadline";
}
#endif  // BBW_FLOOD_TEST

}  // namespace
