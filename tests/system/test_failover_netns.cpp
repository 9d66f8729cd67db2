// A hot-standby CCU across network namespaces (issue 16, docs/faults.md "Hot-standby CCU"): the
// primary CCU, the standby and each corner in its own namespace, joined by veths to a bridge in
// a seventh (netns_support.hpp; UDPv4 on the namespace addresses only, nothing on the host).
//
// - SystemFailoverNetns.PrimaryLinkCut{Realtime,Lockstep}: config/scenarios/faults/
//   ccu_failover_link_cut.yaml; during the held stop the test takes the primary's link down
//   (inside its namespace) for 0.5 s (lockstep: 50 ms) and brings it back. The standby must take
//   every corner over within the goals (realtime: takeover <= 20 ms after the link went down, no
//   command gap over 25 ms, dip <= 0.5 kN, no safe state). Realtime: it keeps them when the
//   primary's link returns (the primary counts the cut as a long outage). Lockstep: nothing is
//   judged by wall time; the returning primary catches up from the repaired blocks, and both
//   CCUs' logs are equal byte for byte.
// - SystemFailoverNetns.SplitBrainEachCornerObeysOneCcu: both CCUs alive, and FL cut off from the
//   primary only (host routes of type blackhole between the two namespaces, both ways: this
//   machine's kernel has no tc actions or netfilter tools) for 1 s. Every corner obeys exactly one
//   writer at a time, the strongest it hears: FL the standby, the others the primary; afterwards
//   FL the primary again (it had no outage). The two CCUs never talk to each other: whether they
//   see each other changes nothing. What this costs (the primary, having lost FL, gives FL's share
//   to FR while FL still brakes under the standby) is measured and printed.
//
// Needs root (GTEST_SKIP otherwise). Domains 66, 67, 68; addresses 10.231.<domain>.10-15.
#include <gtest/gtest.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bbw/common/json.hpp"
#include "bbw/faults/ccu_watchdog.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/node/command_plan.hpp"
#include "bbw/runtime/failover_stats.hpp"
#include "failover_starved.hpp"
#include "failover_summary.hpp"
#include "netns_support.hpp"

namespace {

using namespace bbw::netns_test;
using bbw::system_test::bin;
using bbw::system_test::slurp;
using bbw::system_test::src;

const std::vector<std::string> kRoles = {"ccu", "ccusb", "FL", "FR", "RL", "RR"};
constexpr std::size_t kPrimary = 0, kStandby = 1, kFL = 2;

// The namespaces, addresses and processes of one run. Processes are killed before the
// namespaces are deleted (member order).
class Cluster {
 public:
  Cluster(int domain, const std::string& test) : domain_(domain) {
    tag_ = std::string(kNsPrefix) + std::to_string(::getpid()) + "f" + std::to_string(domain);
    dir_ = (fs::temp_directory_path() / ("bbw_failover_netns_" + test + "_" + std::to_string(::getpid()))).string();
    fs::remove_all(dir_);
    fs::create_directories(dir_ + "/out/standby");
    bbw::system_test::RemoveScratchOnPass::add(dir_);
    guard_ = std::make_unique<Namespaces>(dir_);
  }
  ~Cluster() {
    procs_.clear();  // killed (Child's destructor) before the namespaces go
    guard_.reset();
    sched_param normal{};
    ::sched_setscheduler(0, SCHED_OTHER, &normal);  // back to normal for the next test
  }

  // "" when the namespaces are up; otherwise why not (the test skips).
  std::string build() {
    if (::geteuid() != 0) return "needs root to create network namespaces (ip netns add)";
    if (ip_binary().empty()) return "no ip binary (iproute2)";
    Namespaces::remove_orphans(dir_);
    const std::string br = tag_ + "_br";
    if (const CmdResult r = guard_->add(br); !r.ok) return "cannot create a network namespace: " + r.what;
    must(ip(dir_, {"-n", br, "link", "add", "br0", "type", "bridge"}));
    must(ip(dir_, {"-n", br, "link", "set", "br0", "up"}));
    for (std::size_t i = 0; i < kRoles.size(); ++i) {
      ns_.push_back(tag_ + "_" + kRoles[i]);
      addr_.push_back("10.231." + std::to_string(domain_) + "." + std::to_string(10 + i));
      const std::string port = "p" + std::to_string(i);
      must(guard_->add(ns_[i]));
      must(ip(dir_, {"-n", br, "link", "add", port, "type", "veth", "peer", "name", "bbw0", "netns", ns_[i]}));
      must(ip(dir_, {"-n", br, "link", "set", port, "master", "br0", "up"}));
      must(ip(dir_, {"-n", ns_[i], "addr", "add", addr_[i] + "/24", "dev", "bbw0"}));
      must(ip(dir_, {"-n", ns_[i], "link", "set", "bbw0", "up"}));
      must(ip(dir_, {"-n", ns_[i], "link", "set", "lo", "up"}));
    }
    for (std::size_t i = 0; i < kRoles.size(); ++i) {
      std::vector<std::string> peers;
      for (std::size_t j = 0; j < kRoles.size(); ++j) {
        if (j != i) peers.push_back(addr_[j]);
      }
      profiles_.push_back(dir_ + "/profiles_" + kRoles[i] + ".xml");
      std::ofstream(profiles_.back()) << netns_profiles(addr_[i], peers);
    }
    return failed_;
  }

  void start(const std::string& scenario, const std::string& mode) {
    const std::string out = dir_ + "/out";
    // The test and its `ip` commands under SCHED_FIFO 20 (at normal priority on this loaded
    // machine an `ip` command took 4-311 ms, too loose a bracket around the failure instant); a
    // realtime run's processes under SCHED_FIFO 10 (test_failover_runs.cpp says why), a lockstep
    // run's at normal priority (it needs none, and would starve the `ip` commands).
    sched_param prio{};
    prio.sched_priority = 20;
    if (::sched_setscheduler(0, SCHED_FIFO, &prio) != 0) std::cout << "[ NOTE     ] not under SCHED_FIFO\n";
    auto argv = [&](std::size_t i, std::vector<std::string> own) {
      std::vector<std::string> a{ip_binary(), "netns", "exec", ns_[i], "/usr/bin/chrt"};
      if (mode == "realtime") a.insert(a.end(), {"-f", "10"});
      else a.insert(a.end(), {"-o", "0"});
      a.insert(a.end(), own.begin(), own.end());
      for (const std::string& x : {std::string("--scenario"), src(scenario), std::string("--domain"), std::to_string(domain_),
                                   std::string("--mode"), mode, std::string("--discovery-timeout"), std::string("15"),
                                   std::string("--dds-profiles"), profiles_[i], std::string("--dds-participant-profile"),
                                   std::string("bbw_netns"), std::string("--standby")}) {
        a.push_back(x);
      }
      return a;
    };
    procs_.push_back(std::make_unique<Child>("bbw_ccu", argv(kPrimary, {bin("bbw_ccu"), "--out", out, "--role", "primary"}),
                                             out + "/ccu.out", out + "/ccu.err"));
    procs_.push_back(std::make_unique<Child>(
        "bbw_ccu_standby", argv(kStandby, {bin("bbw_ccu"), "--out", out + "/standby", "--role", "standby"}),
        out + "/ccu_standby.out", out + "/ccu_standby.err"));
    for (std::size_t i = kFL; i < kRoles.size(); ++i) {
      const std::string c = kRoles[i];
      procs_.push_back(std::make_unique<Child>(
          "bbw_corner_" + c,
          argv(i, {bin("bbw_corner"), "--corner", c, "--stats", out + "/corner_" + c + ".stats", "--periods-log",
                   out + "/corner_" + c + "_periods.csv"}),
          out + "/corner_" + c + ".out", out + "/corner_" + c + ".err"));
    }
  }

  // Waits (bounded) until the primary's ccu_periods.csv (stdio-buffered: ~0.35 s behind) shows a
  // period at or after t_s; false if the deadline passes or the primary ends first.
  bool wait_for_sim(double t_s, Clock::time_point deadline) {
    const std::string file = dir_ + "/out/ccu_periods.csv";
    for (;;) {
      std::ifstream f(file);
      std::string line, last;
      while (std::getline(f, line)) {
        if (!f.eof() && !line.empty()) last = line;
      }
      if (!last.empty() && last[0] != 't' && std::stod(last) >= t_s) return true;
      if (Clock::now() >= deadline) return false;
      if (procs_[kPrimary]->wait_until(std::min(deadline, Clock::now() + 20ms))) return false;
    }
  }

  // Every process ends on its own within `limit`; "" when all exited 0, else who did not.
  std::string wait_all(std::chrono::seconds limit) {
    const auto end = Clock::now() + limit;
    std::string bad;
    for (auto& p : procs_) {
      auto st = p->wait_until(end);
      if (!st) st = p->stop(2000ms);
      if (!st->ok()) bad += p->name() + ": " + st->describe() + "; ";
    }
    return bad;
  }

  std::string logs() const {
    std::string s;
    const std::string out = dir_ + "/out";
    for (const char* f : {"ccu", "ccu_standby", "corner_FL", "corner_FR", "corner_RL", "corner_RR"}) {
      s += std::string("--- ") + f + ":\n" + slurp(out + "/" + f + ".out") + slurp(out + "/" + f + ".err");
    }
    return s;
  }

  // Waits until `deadline` unless the primary ends first: true when it ended.
  bool primary_ended_before(Clock::time_point deadline) { return procs_[kPrimary]->wait_until(deadline).has_value(); }

  bool run_ip(const std::vector<std::string>& args) { return must(ip(dir_, args)); }
  const std::string& ns(std::size_t i) const { return ns_[i]; }
  const std::string& addr(std::size_t i) const { return addr_[i]; }
  std::string out() const { return dir_ + "/out"; }

 private:
  bool must(const CmdResult& r) {
    if (!r.ok && failed_.empty()) failed_ = r.what;
    if (!r.ok) ADD_FAILURE() << r.what;
    return r.ok;
  }

  int domain_;
  std::string tag_, dir_, failed_;
  std::unique_ptr<Namespaces> guard_;
  std::vector<std::string> ns_, addr_, profiles_;
  std::vector<std::unique_ptr<Child>> procs_;
};

void print(const std::string& what, const bbw::launch::FailoverResult& r) {
  std::cout << "[ MEASURED ] " << what << ": takeover_ms=" << r.takeover_ms << " takeover_gap_ms=" << r.takeover_gap_ms
            << " max_command_gap_ms=" << r.max_command_gap_ms << " max_command_gap_wall_ms=" << r.max_command_gap_wall_ms
            << " max_force_dip_kN=" << r.max_force_dip_kN << " safe_state_entered=" << r.safe_state_entered
            << " switches_before_failure=" << r.switches_before_failure << " switches_back_to_primary="
            << r.switches_back_to_primary << " primary_outages=" << r.primary_outages << " standby_outages="
            << r.standby_outages << " stalls=" << r.primary_stalls << "/" << r.standby_stalls
            << " owners_at_end=" << r.owners_at_end << std::endl;
}

// One run of the link cut; `again` is set (and nothing judged) when a realtime run before the
// last attempt was decided by the machine (failover_starved.hpp: both CCUs stalled at once, or
// the standby across the takeover; a ctest pass saw both CCUs silent together for 19 ms and every
// corner 30-38 ms without a command, past its 20 ms watchdog), as the failover runs over one
// host do.
void link_cut_once(const std::string& mode, int domain, int attempt, bool& again) {
  Cluster c(domain, "link_cut_" + mode);
  if (const std::string why = c.build(); !why.empty()) GTEST_SKIP() << why;
  const std::string scenario = "config/scenarios/faults/ccu_failover_link_cut.yaml";
  const auto loaded = bbw::faults::load_fault_scenario(src(scenario));
  ASSERT_EQ(loaded.faults.faults.size(), 1u);
  const bbw::faults::FaultSpec& cut = loaded.faults.faults[0];
  ASSERT_EQ(cut.type, bbw::faults::FaultType::LinkCut);
  c.start(scenario, mode);
  // The cut, at the scenario's time as far as the test can see it (the CCU's log lags ~0.35 s).
  ASSERT_TRUE(c.wait_for_sim(cut.at_s - 0.3, Clock::now() + 40s)) << "the run did not reach the cut\n" << c.logs();
  // The link goes down by an ioctl from a thread in the primary's namespace: the failure instant is
  // known to microseconds (an `ip` command took 3-90 ms even at real-time priority).
  double down_mono_s = 0.0, down_after_s = 0.0, up_before_s = 0.0, up_after_s = 0.0;
  const std::string down_error = set_link(c.ns(kPrimary), "bbw0", false, down_mono_s, down_after_s);
  ASSERT_EQ(down_error, "");
  std::cout << "[ NOTE     ] the link went down within " << 1e6 * (down_after_s - down_mono_s) << " us" << std::endl;
  // Hold the link down for the scenario's duration (wall time: the outage is the stimulus); the
  // wait ends early only if the primary exits, itself a failure. Lockstep: 50 ms, so that the link
  // returns while the corners still run under the standby (an unloaded run's remaining 1.6 s of
  // simulated time take ~0.2 s of wall time) and the returning primary's catch-up is exercised.
  const double hold_s = mode == "lockstep" ? std::min(0.05, *cut.duration_s) : *cut.duration_s;
  const bool primary_ended = c.primary_ended_before(Clock::now() + std::chrono::milliseconds(static_cast<int>(1e3 * hold_s)));
  ASSERT_EQ(set_link(c.ns(kPrimary), "bbw0", true, up_before_s, up_after_s), "");
  const std::string bad = c.wait_all(60s);

  auto in = bbw::launch::load_failover_input(loaded.scenario, c.out(), mode == "lockstep");
  // The corners hear the standby alone until the link is back and the primary rediscovered (a
  // 100 ms margin for that, not measured).
  const double watchdog_s = bbw::faults::CcuWatchdogParams{}.timeout_s;
  if (const std::string starved = mode == "realtime" && attempt < 3
                                      ? bbw::system_test::ccus_starved(in.primary, in.standby, down_mono_s, up_after_s + 0.1,
                                                                       watchdog_s - loaded.scenario.ccu_period_s)
                                      : "";
      !starved.empty()) {
    std::cout << "[ NOTE     ] run " << attempt << " of the link cut not judged: " << starved << "; running it again" << std::endl;
    again = true;
    return;
  }
  EXPECT_FALSE(primary_ended) << c.logs();
  EXPECT_EQ(bad, "") << c.logs();
  in.failure = "link_cut";
  in.failed_mono_s = down_mono_s;
  // Realtime: the primary's simulated time at the cut. Lockstep: simulated time is the corners'
  // progress; the cut is placed at the last period the primary granted before it.
  in.failed_sim_s = mode == "realtime" ? down_mono_s - in.primary.t0_mono_s : -1.0;
  if (mode == "lockstep") {
    // The standby's first command after the cut names the period the corners waited for.
    double first = 1e9;
    for (const auto& ci : in.corners) {
      for (const auto& sw : ci.owners.switches) {
        if (sw.mono_s >= down_mono_s && sw.to == "standby") first = std::min(first, sw.sim_s);
      }
    }
    in.failed_sim_s = first < 1e9 ? first : cut.at_s;
  }
  const bbw::launch::FailoverResult r = bbw::launch::assess_failover(in);
  print("ccu_failover_link_cut " + mode, r);
  {
    bbw::json::Writer j;
    j.begin_object();
    bbw::launch::write_failover(j, r);
    j.end_object();
    j.save(c.out() + "/failover.json");
  }
  EXPECT_EQ(r.takeover_missing, "") << c.logs();
  if (mode == "realtime") {
    EXPECT_GT(r.takeover_ms, 0.0);
    EXPECT_LE(r.takeover_ms, 20.0) << "goal: takeover <= 20 ms after the failure";
    EXPECT_LE(r.takeover_gap_ms, 25.0) << "goal: no command gap over 25 ms";
  } else {
    EXPECT_NEAR(r.max_command_gap_ms, 5.0, 1e-6);  // simulated: one period, always
  }
  EXPECT_LE(r.max_force_dip_kN, 0.5) << "goal: clamp-force dip <= 0.5 kN";
  {
    // On a failure: both CCUs' and the corners' own stalls, in ms from the cut (the link came back
    // at `up`), beside when the corners entered their safe state.
    auto stalls = [&](const std::vector<bbw::runtime::StallInterval>& v) {
      std::string out;
      for (const auto& st : v) out += " [" + std::to_string(1e3 * (st.from_mono_s - down_mono_s)) + ", " + std::to_string(1e3 * (st.to_mono_s - down_mono_s)) + "]";
      return out + "\n";
    };
    std::string own;
    for (const auto& ci : in.corners) own += "  " + ci.owners.corner + "'s own:" + stalls(ci.owners.stall_intervals);
    EXPECT_FALSE(r.safe_state_entered) << "safe state at " << r.safe_state_s << " s (" << 1e3 * (in.primary.t0_mono_s + r.safe_state_s - down_mono_s)
                                       << " ms after the cut; the link came back at " << 1e3 * (up_after_s - down_mono_s) << " ms)\n"
                                       << "stalls, ms after the cut: the primary's" << stalls(in.primary.stall_intervals)
                                       << "  the standby's" << stalls(in.standby.stall_intervals) << own << c.logs();
  }
  if (mode == "realtime") {
    // The primary found itself cut off (a long outage) and leaves the corners to the standby.
    EXPECT_GE(in.primary.outages, 1u) << c.logs();
    EXPECT_EQ(in.standby.outages, 0u) << c.logs();
    EXPECT_EQ(r.owners_at_end, "standby,standby,standby,standby") << c.logs();
  } else {
    // Lockstep judges nothing by wall time (a loaded machine silences the corners like a cut):
    // no outage on either side. The primary caught up from the repaired blocks and ran to the
    // end: both CCUs computed every period, and their logs are equal byte for byte (who led at
    // the end depends on when the link came back, and changes no log).
    EXPECT_EQ(in.primary.outages, 0u) << c.logs();
    EXPECT_EQ(in.standby.outages, 0u) << c.logs();
    EXPECT_EQ(in.primary.periods_done, in.standby.periods_done) << c.logs();
    for (const std::string corner : {"FL", "FR", "RL", "RR"}) {
      const std::string primary = slurp(c.out() + "/ccu_" + corner + ".csv");
      const std::string standby = slurp(c.out() + "/standby/ccu_" + corner + ".csv");
      EXPECT_GT(primary.size(), 1000u) << corner;
      EXPECT_TRUE(primary == standby) << "ccu_" << corner << ".csv: the two CCUs differ\n" << c.logs();
    }
  }
}

void link_cut(const std::string& mode, int domain) {
  for (int attempt = 1;; ++attempt) {
    bool again = false;
    link_cut_once(mode, domain, attempt, again);
    if (!again || ::testing::Test::HasFatalFailure()) return;
  }
}

TEST(SystemFailoverNetns, PrimaryLinkCutRealtime) { link_cut("realtime", 66); }
TEST(SystemFailoverNetns, PrimaryLinkCutLockstep) { link_cut("lockstep", 68); }

// One run of the split brain; `again` is set (and nothing judged) when a run before the last
// attempt was decided by the machine around FL's takeover: the standby or FL itself stalled
// within 25 ms of FL's last command from the primary, or both CCUs at once
// (failover_starved.hpp; FL's own stalls are its periods begun 10 ms late or more).
void split_brain_once(int attempt, bool& again) {
  Cluster c(67, "split");
  if (const std::string why = c.build(); !why.empty()) GTEST_SKIP() << why;
  const std::string scenario = "config/scenarios/faults/ccu_failover_link_cut.yaml";  // its cut is not carried out here
  const auto loaded = bbw::faults::load_fault_scenario(src(scenario));
  c.start(scenario, "realtime");
  ASSERT_TRUE(c.wait_for_sim(3.0, Clock::now() + 40s)) << c.logs();
  // FL and the primary lose each other (both directions); everyone else hears everyone.
  // The split begins when the first route is in place (the primary's commands to FL stop),
  // between the start and the end of that `ip` command: times are measured from its start (an
  // upper bound). It ends when the first is removed.
  const double split_mono_s = bbw::runtime::mono_now_s();
  ASSERT_TRUE(c.run_ip({"-n", c.ns(kPrimary), "route", "add", "blackhole", c.addr(kFL) + "/32"}));
  std::cout << "[ NOTE     ] ip route add took " << 1e3 * (bbw::runtime::mono_now_s() - split_mono_s) << " ms" << std::endl;
  ASSERT_TRUE(c.run_ip({"-n", c.ns(kFL), "route", "add", "blackhole", c.addr(kPrimary) + "/32"}));
  const bool primary_ended = c.primary_ended_before(Clock::now() + 1s);
  const double heal_mono_s = bbw::runtime::mono_now_s();
  ASSERT_TRUE(c.run_ip({"-n", c.ns(kPrimary), "route", "del", "blackhole", c.addr(kFL) + "/32"}));
  ASSERT_TRUE(c.run_ip({"-n", c.ns(kFL), "route", "del", "blackhole", c.addr(kPrimary) + "/32"}));
  EXPECT_FALSE(primary_ended) << c.logs();
  EXPECT_EQ(c.wait_all(60s), "") << c.logs();

  const auto in = bbw::launch::load_failover_input(loaded.scenario, c.out(), false);
  // FL's takeover by the standby, as FL lived it: from the primary's last command it took to the
  // standby's first (the switch's gap). Not from the split's start: the cut takes effect
  // somewhere inside `ip route add`, which took 13-20 ms to run on one machine.
  double fl_takeover_ms = -1.0, fl_takeover_from_split_ms = -1.0, fl_last_primary_mono_s = split_mono_s;
  for (const auto& sw : in.corners[0].owners.switches) {
    if (sw.mono_s >= split_mono_s && sw.to == "standby") {
      fl_takeover_ms = sw.gap_ms;
      fl_takeover_from_split_ms = 1e3 * (sw.mono_s - split_mono_s);
      fl_last_primary_mono_s = sw.mono_s - 1e-3 * sw.gap_ms;
      break;
    }
  }
  if (attempt < 3) {
    std::string starved = bbw::system_test::ccus_starved(in.primary, in.standby, fl_last_primary_mono_s);
    for (const auto& st : in.corners[0].owners.stall_intervals) {
      if (starved.empty() && st.to_mono_s >= fl_last_primary_mono_s && st.from_mono_s <= fl_last_primary_mono_s + 0.025) {
        starved = "FL itself stalled from " + std::to_string(1e3 * (st.from_mono_s - fl_last_primary_mono_s)) + " to " +
                  std::to_string(1e3 * (st.to_mono_s - fl_last_primary_mono_s)) +
                  " ms after its last command from the primary (starved of the CPU)";
      }
    }
    if (!starved.empty()) {
      std::cout << "[ NOTE     ] run " << attempt << " of the split brain not judged: " << starved << "; running it again" << std::endl;
      again = true;
      return;
    }
  }
  // Whose commands each corner applied, in (split + 50 ms, heal): one writer per corner.
  auto owner_in = [&](const bbw::runtime::CornerFailoverStats& s, double from, double to) {
    std::string owner = "none";
    std::vector<std::string> seen;
    for (const auto& sw : s.switches) {
      if (sw.mono_s < from) owner = sw.to;
      else if (sw.mono_s < to) seen.push_back(sw.to);
    }
    if (owner != "none") seen.insert(seen.begin(), owner);
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
    std::string out;
    for (const auto& x : seen) out += (out.empty() ? "" : "+") + x;
    return out;
  };
  const double settle_s = 0.05;  // FL's deadline (10 ms) and the standby's next command, with margin
  // A corner that hears the primary still goes to the standby while the primary's commands miss
  // the corners' 10 ms deadline (docs/faults.md "Who commands"): that is the hot standby working,
  // not split brain. Such a visit is explained when it begins within a stall of the primary (its
  // own sends further apart than the deadline, recorded by the primary; the corner takes it up to
  // one command period later) or after the corner itself took nothing for a deadline (a stall of
  // the corner), and it ends within `visit_max_s` (the primary's next command, with margin).
  const double deadline_ms = 10.0, visit_max_s = 0.05;
  const double period_s = loaded.scenario.ccu_period_s;
  auto explained = [&](const bbw::runtime::OwnerSwitch& sw) {
    if (sw.gap_ms >= deadline_ms) return true;
    for (const auto& st : in.primary.stall_intervals) {
      if (sw.mono_s >= st.from_mono_s + 1e-3 * deadline_ms && sw.mono_s <= st.to_mono_s + 2.0 * period_s) return true;
    }
    return false;
  };
  // A corner's safe-state entry at sim time lost_s is explained by a stall of the whole machine
  // when the two CCUs' own stalls (their commands further apart than the deadline) overlapped for
  // at least the corner's watchdog timeout less a command period, and the corner declared them
  // lost within that overlap or a period after it (mono time from the primary's clock start).
  // (Stalls less than a period apart are one: a single command between them is no recovery.)
  const double watchdog_s = bbw::faults::CcuWatchdogParams{}.timeout_s;
  auto merged = [&](const std::vector<bbw::runtime::StallInterval>& v) {
    std::vector<bbw::runtime::StallInterval> out;
    for (const auto& st : v) {
      if (!out.empty() && st.from_mono_s - out.back().to_mono_s < period_s) out.back().to_mono_s = std::max(out.back().to_mono_s, st.to_mono_s);
      else out.push_back(st);
    }
    return out;
  };
  const auto primary_stalls = merged(in.primary.stall_intervals), standby_stalls = merged(in.standby.stall_intervals);
  auto stalled_together = [&](double lost_s) {
    const double lost_mono_s = in.primary.t0_mono_s + lost_s;
    for (const auto& a : primary_stalls) {
      for (const auto& b : standby_stalls) {
        const double from = std::max(a.from_mono_s, b.from_mono_s), to = std::min(a.to_mono_s, b.to_mono_s);
        if (to - from >= watchdog_s - period_s && lost_mono_s >= from + watchdog_s - period_s && lost_mono_s <= to + period_s) {
          return true;
        }
      }
    }
    return false;
  };
  // Stalls as "from to to s" after the split, as the switches are listed.
  auto after_split = [&](const std::vector<bbw::runtime::StallInterval>& v) {
    std::string out;
    for (const auto& st : v) {
      out += "  " + std::to_string(st.from_mono_s - split_mono_s) + " to " + std::to_string(st.to_mono_s - split_mono_s) + " s\n";
    }
    return out;
  };
  int stall_visits = 0;
  for (std::size_t i = 0; i < in.corners.size(); ++i) {
    const auto& s = in.corners[i].owners;
    const std::string expected = s.corner == "FL" ? "standby" : "primary";
    std::string trail, unexplained;
    for (std::size_t j = 0; j < s.switches.size(); ++j) {
      const auto& sw = s.switches[j];
      const std::string line = "  " + sw.from + " -> " + sw.to + " at " + std::to_string(sw.mono_s - split_mono_s) +
                               " s after the split, " + std::to_string(sw.gap_ms) + " ms after the command before\n";
      trail += line;
      if (sw.mono_s < split_mono_s + settle_s || sw.mono_s >= heal_mono_s || sw.to == expected) continue;
      const bool back_soon = j + 1 < s.switches.size() && s.switches[j + 1].to == expected &&
                             s.switches[j + 1].mono_s - sw.mono_s <= visit_max_s;
      if (s.corner != "FL" && explained(sw) && back_soon) ++stall_visits;
      else unexplained += line;
    }
    EXPECT_EQ(owner_in(s, split_mono_s + settle_s, split_mono_s + settle_s), expected) << s.corner << " as the split settled";
    EXPECT_EQ(unexplained, "") << s.corner << " went to another CCU during the split without a stall to explain it; its switches:\n"
                               << trail << "the primary's stalls (" << in.primary.stalls << "):\n" << after_split(in.primary.stall_intervals)
                               << "its own (" << s.stalls << "):\n" << after_split(s.stall_intervals) << c.logs();
    EXPECT_EQ(owner_in(s, heal_mono_s + 0.5, 1e12), "primary") << s.corner << " after the split healed\n" << c.logs();
    if (in.corners[i].ccu_lost_s >= 0.0 && stalled_together(in.corners[i].ccu_lost_s)) {
      // Both CCUs silent at once for the corner's watchdog timeout: the machine stalled (a
      // clean-clone CI run: both 33 ms together, the corner's own jitter 43 ms). Not split brain:
      // reported, not failed.
      std::cout << "[ NOTE     ] " << s.corner << " entered its safe state at " << in.corners[i].ccu_lost_s
                << " s while both CCUs were stalled together (a machine stall, not split brain)" << std::endl;
    } else {
      // On a failure, both CCUs' stalls beside when the corner entered its safe state (all after
      // the split): whether they overlapped, and for how long, says if the machine did it.
      EXPECT_LT(in.corners[i].ccu_lost_s, 0.0)
          << s.corner << ": safe state entered at " << in.primary.t0_mono_s + in.corners[i].ccu_lost_s - split_mono_s
          << " s after the split\nthe primary's stalls (" << in.primary.stalls << "):\n" << after_split(primary_stalls)
          << "the standby's (" << in.standby.stalls << "):\n" << after_split(standby_stalls) << "its own (" << s.stalls
          << "):\n" << after_split(s.stall_intervals) << "its switches of CCU:\n" << trail << c.logs();
    }
  }
  // FL's takeover: within the goal. The split took effect after FL's last command from the
  // primary, so the gap bounds the takeover from above.
  // The cut came after FL's last command from the primary and before the primary's next one was
  // due (a period later): the takeover lies within [gap - period, gap]. So the gap is judged
  // against the goal for command gaps (25 ms), which is also the takeover goal (20 ms) on the
  // takeover's least value: the cut's instant is known no better here (the link cut's test knows
  // it to microseconds and judges the takeover itself).
  EXPECT_GT(fl_takeover_ms, 0.0);
  EXPECT_LE(fl_takeover_ms, 20.0 + 1e3 * period_s)
      << "goals: no command gap over 25 ms, takeover <= 20 ms (at least the gap less a period); from the split's start "
      << fl_takeover_from_split_ms << " ms";
  // What split brain costs: the primary lost FL and gave FL's share to FR, while FL still brakes
  // under the standby. The total true clamp force against the demand during the split.
  const bbw::ccu::CommandPlanner planner(loaded.scenario);
  const double t0 = in.primary.t0_mono_s;
  double worst_excess_kN = 0.0, demand_at_worst = 0.0;
  const auto& periods0 = in.corners[0].periods;
  for (std::size_t k = 0; k < periods0.size(); ++k) {
    const double t_end = periods0[k].first;
    if (t_end < split_mono_s - t0 + 0.1 || t_end > heal_mono_s - t0) continue;
    double demand = 0.0, delivered = 0.0;
    for (std::size_t i = 0; i < in.corners.size(); ++i) {
      if (k >= in.corners[i].periods.size()) continue;
      delivered += in.corners[i].periods[k].second;
      demand += planner.at(i, t_end - loaded.scenario.ccu_period_s).clamp_force_kN;
    }
    if (delivered - demand > worst_excess_kN) {
      worst_excess_kN = delivered - demand;
      demand_at_worst = demand;
    }
  }
  std::cout << "[ NOTE     ] corners that visited the standby during a stall of the primary: " << stall_visits << std::endl;
  std::cout << "[ MEASURED ] split brain (FL cut off from the primary for 1 s): FL taken over by the standby after "
            << fl_takeover_ms << " ms without a command (the takeover at least a period less; " << fl_takeover_from_split_ms << " ms from the start of `ip route add`); total clamp force above demand by up to " << worst_excess_kN << " kN (demand "
            << demand_at_worst << " kN)" << std::endl;
}

TEST(SystemFailoverNetns, SplitBrainEachCornerObeysOneCcu) {
  for (int attempt = 1;; ++attempt) {
    bool again = false;
    split_brain_once(attempt, again);
    if (!again || ::testing::Test::HasFatalFailure()) return;
  }
}

}  // namespace
