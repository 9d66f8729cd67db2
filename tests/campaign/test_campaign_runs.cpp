// ./bbw campaign over real processes (docs/faults.md, "Campaigns"): the CI subset over Fast DDS
// (each run on a free domain of the launcher's range 100-159, GNU parallel, 2 jobs), resuming
// after a kill, and the in-memory transport scoring a run as the DDS processes do.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <cstdlib>
#include <fstream>
#include <set>
#include <string>

#include "system_test_support.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using bbw::system_test::bin;
using bbw::system_test::slurp;
using bbw::system_test::src;

namespace {

// `./bbw campaign ARGS` (scripts/bbw-campaign.sh). `bare_env`: without SHELL and HOME, as a CI
// job's environment may be (GNU parallel's remote wrapper then needs its ssh to supply SHELL).
bbw::system_test::ProcessRun campaign(const std::string& dir, const std::string& name, const std::vector<std::string>& args,
                                      std::chrono::seconds limit, bool bare_env = false) {
  std::vector<std::string> argv{"/bin/bash", src("scripts/bbw-campaign.sh")};
  if (bare_env) argv.insert(argv.begin(), {"/usr/bin/env", "-u", "SHELL", "-u", "HOME"});
  argv.insert(argv.end(), args.begin(), args.end());
  return bbw::system_test::run(name, argv, dir, limit, {"BBW_BUILD_DIR=" + std::string(BBW_TEST_BINARY_DIR)});
}

std::string small_spec(const std::string& dir, int runs) {
  const std::string file = dir + "/small.yaml";
  std::ofstream(file) << "name: small\nseed: 77\nruns: " << runs
                      << "\nfault_free_share: 0.34\nduration_s: [12, 12]\npopulation: {spec: "
                      << src("config/population/scoring.yaml")
                      << ", members: 30}\ntemperatures_C: [28, 54]\neffects_share: 0.3\neffects: [viscous_friction, sensor_delay, backlash]\n"
                         "profiles: [city, hard_stop_release]\nfaults:\n  kinds: [bias, total_loss, dropout]\n"
                         "  onsets: [normal]\n  two_faults_share: 0\n  same_corner_share: 0\n  intermittent_share: 0\n";
  return file;
}

// The small spec with one piece of it replaced (`from` must be in it).
std::string small_spec_with(const std::string& dir, int runs, const std::string& from, const std::string& to) {
  const std::string file = small_spec(dir, runs);
  std::string text = slurp(file);
  text.replace(text.find(from), from.size(), to);
  std::ofstream(file) << text;
  return file;
}

}  // namespace

// The CI subset (config/campaigns/ci.yaml, 36 runs, every kind, onset and profile): every fault
// above its limit detected rightly within its window, and nothing else raised.
// The goal for this subset is every fault detected and no false alarm: reached since the
// nineteenth session (39 of 39, 0, 0; 38 of 39 scoring windows from the injection, before a
// fault hidden by a link silence was scored from the link's return). Before (docs/faults.md,
// "Diagnosis across calipers and driving": 32 of 39 detected,
// 1 + 1 false alarms with the fourth session's rules (2026-11-26); 25 of 39, 1 + 2 with only
// credible fits judged, 2 + 8 before, 3 + 9 after the local loop's
// fix, 5 + 13 before it, measured 2026-11-23). Lockstep runs are deterministic, so the subset is a
// ratchet: it fails when the diagnosis gets worse than measured, and its bounds move to the goal
// as the diagnosis improves (kMinDetected up to n, the false-alarm bounds down to 0).
TEST(CampaignSystem, CiSubsetOverDdsIsNoWorseThanMeasured) {
  constexpr int kMinDetected = 39;             // the goal: every fault, since the nineteenth session's masked-fault scoring (a fault hidden by a link silence scored from the link's return; 38 before, 36 before the sixteenth session, 35 before the fifteenth, 34 before the thirteenth, 32 before the twelfth, 25 before the fourth session's rules)
  constexpr int kMaxFalseAlarmsFaultFree = 0;  // the goal, met since the fifth session (1 before it, 2 before credible fits, 3 before the friction memory, 5 before the local loop's fix)
  constexpr int kMaxFalseAlarmsFaulty = 0;     // the goal, met since the sixth session (1 before it; 2 before the fourth session's rules, 8 before credible fits, 9 before the friction memory, 13 before the local loop's fix)
  const std::string dir = bbw::system_test::scratch("campaign", "ci");
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = campaign(dir, "ci", {src("config/campaigns/ci.yaml"), "--out", dir + "/c", "--jobs", "2"}, 300s);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.err;
  const YAML::Node c = YAML::LoadFile(dir + "/c/campaign.json");
  EXPECT_EQ(c["runs_missing"].as<int>(), 0);
  EXPECT_EQ(c["runs_failed"].as<int>(), 0) << r.err;
  const int n = c["overall"]["faults"].as<int>();
  EXPECT_GE(n, 30);
  const int detected = c["overall"]["detected"].as<int>();
  const int fa_free = c["false_alarms"]["in_fault_free_runs"].as<int>();
  const int fa_faulty = c["false_alarms"]["in_faulty_runs"].as<int>();
  EXPECT_GE(detected, kMinDetected) << slurp(dir + "/c/campaign.json");
  // Every fault counted once per plant effect of its corner ("none" without one).
  int by_effect = 0;
  for (const auto& e : c["by_effect"]) by_effect += e.second["faults"].as<int>();
  EXPECT_EQ(by_effect, c["overall"]["faults"].as<int>());
  EXPECT_LE(fa_free, kMaxFalseAlarmsFaultFree) << slurp(dir + "/c/campaign.json");
  EXPECT_LE(fa_faulty, kMaxFalseAlarmsFaulty) << slurp(dir + "/c/campaign.json");
  std::cout << "CI subset: " << detected << " of " << n << " faults detected (goal: all), false alarms " << fa_free
            << " in fault-free runs and " << fa_faulty << " in faulty runs (goal: 0)\n";
  for (const char* png : {"coverage.png", "latency.png", "harm.png"}) {
    EXPECT_GT(fs::file_size(dir + "/c/plots/" + png), 1000u) << png;
  }
  EXPECT_NE(slurp(dir + "/c/report.html").find("plots/coverage.png"), std::string::npos);
  EXPECT_LT(wall_s, 180.0) << "the CI subset must stay within 3 min";
  std::cout << "CI subset: " << n << " faults, " << wall_s << " s\n";
  if (!HasFailure()) fs::remove_all(dir);
}

// A spec that draws members the population does not have is refused at the plan, naming the file,
// line, key and the population's count (before: every run drawing such a member ended without a
// result, 289 of tune_c's 600 when it first asked for 60 members of a 30-member population).
TEST(CampaignSystem, MembersBeyondThePopulationAreRefusedAtThePlan) {
  const std::string dir = bbw::system_test::scratch("campaign", "members");
  const std::string spec = small_spec_with(dir, 3, "members: 30", "members: 31");
  const auto r = bbw::system_test::run("plan", {bin("bbw_campaign"), "plan", spec, "--out", dir + "/c"}, dir, 60s);
  EXPECT_FALSE(r.status.ok());
  EXPECT_NE(r.err.find(spec + ":6: key 'population.members': must be at most the population's count (30 in "),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/c/runs/00000/scenario.yaml"));
}

// A fault-free campaign (tune_c.yaml hunts false alarms so) reports its false-alarm rate and no
// coverage: not "0/0 (0.00 %)", and no empty plots (gnuplot refused their empty range and the
// campaign said "plots not written").
TEST(CampaignSystem, AFaultFreeCampaignReportsItsFalseAlarmRateAndNoCoverage) {
  const std::string dir = bbw::system_test::scratch("campaign", "fault_free");
  const std::string spec = small_spec_with(dir, 2, "fault_free_share: 0.34", "fault_free_share: 1.0");
  const auto r = campaign(dir, "ff", {spec, "--out", dir + "/c", "--jobs", "2", "--transport", "memory"}, 120s);
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << r.err;
  EXPECT_NE(r.out.find("small: no fault injected, false alarms 0 in 0.01 h fault-free"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("plots not written"), std::string::npos) << r.err;
  const YAML::Node c = YAML::LoadFile(dir + "/c/campaign.json");
  EXPECT_EQ(c["overall"]["faults"].as<int>(), 0);
  EXPECT_EQ(c["false_alarms"]["fault_free_runs"].as<int>(), 2);
  EXPECT_GT(c["false_alarms"]["per_hour_upper95"].as<double>(), 0.0);  // 0 seen is not a 0 rate
  // Per plant effect of the corner: every corner's fault-free hours are counted once.
  double corner_hours = 0.0;
  for (const auto& e : c["false_alarms_by_effect"]) corner_hours += e.second["fault_free_corner_hours"].as<double>();
  EXPECT_NEAR(corner_hours, 4.0 * c["false_alarms"]["fault_free_hours"].as<double>(), 1e-6);
  EXPECT_NE(slurp(dir + "/c/report.html").find("No fault was injected"), std::string::npos);
}

// A campaign killed mid-way (a run without its result, a half-written result, a run's leftover
// logs) resumes: the same command runs only what is missing and leaves finished results alone.
TEST(CampaignSystem, AKilledCampaignResumesAndRunsOnlyWhatIsMissing) {
  const std::string dir = bbw::system_test::scratch("campaign", "resume");
  const std::string spec = small_spec(dir, 6);
  const auto first = campaign(dir, "first", {spec, "--out", dir + "/c", "--jobs", "2", "--transport", "memory"}, 120s);
  ASSERT_TRUE(first.status.ok()) << first.err;
  const std::string before = slurp(dir + "/c/campaign.json");
  const auto kept_time = fs::last_write_time(dir + "/c/runs/00001/result.json");
  // As a kill leaves it: run 3 had no result yet (its rename never happened), its logs half there.
  fs::remove(dir + "/c/runs/00003/result.json");
  std::ofstream(dir + "/c/runs/00003/result.json.tmp") << "{\"index\": 3, \"trunc";
  fs::create_directories(dir + "/c/runs/00003/out");
  // The report of a campaign with a run missing says so and fails: its figures are not a result.
  const auto partial = bbw::system_test::run("partial", {bin("bbw_campaign"), "report", dir + "/c"}, dir, 60s);
  EXPECT_EQ(partial.status.code, 1) << partial.status.describe() << partial.err;
  EXPECT_NE(partial.err.find("1 of 6 runs have no result"), std::string::npos) << partial.err;
  const auto second = campaign(dir, "second", {spec, "--out", dir + "/c", "--jobs", "2", "--transport", "memory"}, 120s);
  ASSERT_TRUE(second.status.ok()) << second.err;
  EXPECT_NE(second.err.find("6 runs, 1 to run, 5 done before"), std::string::npos) << second.err;
  EXPECT_NE(second.err.find("6/6 runs done"), std::string::npos) << second.err;
  EXPECT_EQ(fs::last_write_time(dir + "/c/runs/00001/result.json"), kept_time);
  // The resumed campaign scores as the uninterrupted one (run 3 is drawn and run again alike).
  const YAML::Node a = YAML::Load(before), b = YAML::LoadFile(dir + "/c/campaign.json");
  for (const char* k : {"faults", "detected", "correct", "latency_p50_ms", "latency_max_ms", "harm_max_force_error_kN",
                        "after_detection_estimate_error_max_kN"}) {
    EXPECT_EQ(a["overall"][k].as<std::string>(), b["overall"][k].as<std::string>()) << k;
  }
  EXPECT_EQ(a["false_alarms"]["in_fault_free_runs"].as<int>(), b["false_alarms"]["in_fault_free_runs"].as<int>());
  // Another spec into the same folder is refused.
  std::ofstream(spec, std::ios::app) << "# changed\n";
  const auto other = campaign(dir, "other", {spec, "--out", dir + "/c", "--transport", "memory"}, 60s);
  EXPECT_EQ(other.status.code, 2);
  EXPECT_NE(other.err.find("holds another campaign"), std::string::npos) << other.err;
  if (!HasFailure()) fs::remove_all(dir);
}

// One run scored over Fast DDS and in memory: the same findings at the same times (the node cores
// write byte-identical lockstep logs over both transports).
TEST(CampaignSystem, DdsAndMemoryScoreARunAlike) {
  const std::string dir = bbw::system_test::scratch("campaign", "transports");
  const std::string spec = small_spec(dir, 3);
  for (const char* t : {"dds", "memory"}) {
    const auto r = campaign(dir, std::string("c_") + t, {spec, "--out", dir + "/" + t, "--jobs", "2", "--transport", t}, 200s);
    ASSERT_TRUE(r.status.ok()) << t << "\n" << r.err;
  }
  for (int i = 0; i < 3; ++i) {
    char run[16];
    std::snprintf(run, sizeof run, "%05d", i);
    const YAML::Node a = YAML::LoadFile(dir + "/dds/runs/" + run + "/result.json");
    const YAML::Node b = YAML::LoadFile(dir + "/memory/runs/" + run + "/result.json");
    EXPECT_TRUE(a["ok"].as<bool>() && b["ok"].as<bool>()) << a["error"].as<std::string>() << b["error"].as<std::string>();
    ASSERT_EQ(a["faults"].size(), b["faults"].size());
    for (std::size_t k = 0; k < a["faults"].size(); ++k) {
      EXPECT_EQ(a["faults"][k]["detected"].as<bool>(), b["faults"][k]["detected"].as<bool>()) << run;
      EXPECT_DOUBLE_EQ(a["faults"][k]["latency_ms"].as<double>(), b["faults"][k]["latency_ms"].as<double>()) << run;
      EXPECT_DOUBLE_EQ(a["faults"][k]["harm_force_error_kN"].as<double>(), b["faults"][k]["harm_force_error_kN"].as<double>()) << run;
      if (a["faults"][k]["detected"].as<bool>()) {  // (null while undetected)
        const double after = a["faults"][k]["after_estimate_error_kN"].as<double>();
        EXPECT_TRUE(std::isfinite(after) && after >= 0.0) << run;
        EXPECT_DOUBLE_EQ(after, b["faults"][k]["after_estimate_error_kN"].as<double>()) << run;
      }
    }
    EXPECT_EQ(a["false_alarms"].size(), b["false_alarms"].size()) << run;
  }
  if (!HasFailure()) fs::remove_all(dir);
}

// Two Linux network namespaces as two GNU parallel hosts (scripts/netns-ssh.sh as its ssh): every
// run goes over Fast DDS inside one of them, and both are used. Root only (else skipped); the
// namespaces are deleted at the end, also on failure. The campaign runs without SHELL and HOME
// in its environment, as in CI, where GNU parallel's remote wrapper once ran no job at all and
// still ended with status 0 (netns-ssh.sh now supplies them, as an ssh login does).
TEST(CampaignSystem, TwoNetworkNamespacesServeAsTwoHosts) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root (ip netns add)";
  const std::string a = "bbwcmp" + std::to_string(::getpid()) + "_a", b = "bbwcmp" + std::to_string(::getpid()) + "_b";
  struct Namespaces {
    std::vector<std::string> names;
    ~Namespaces() {
      for (const auto& n : names) std::system(("ip netns del " + n + " 2>/dev/null").c_str());
    }
  } guard{{a, b}};
  for (const auto& n : {a, b}) {
    if (std::system(("ip netns add " + n + " && ip -n " + n + " link set lo up").c_str()) != 0) {
      GTEST_SKIP() << "ip netns add " << n << " failed";
    }
  }
  const std::string dir = bbw::system_test::scratch("campaign", "netns");
  const std::string spec = small_spec(dir, 4);
  const auto r = campaign(dir, "hosts",
                          {spec, "--out", dir + "/c", "--jobs", "2", "--ssh", src("scripts/netns-ssh.sh"), "--sshlogin",
                           "1/" + a, "--sshlogin", "1/" + b},
                          200s, /*bare_env=*/true);
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
  std::set<std::string> hosts;
  std::string where;  // which run went where, for the failure message
  for (int i = 0; i < 4; ++i) {
    char run[16];
    std::snprintf(run, sizeof run, "%05d", i);
    const std::string rd = dir + "/c/runs/" + run;
    ASSERT_TRUE(fs::exists(rd + "/result.json")) << run << " has no result\n" << r.out << r.err;
    const YAML::Node res = YAML::LoadFile(rd + "/result.json");
    EXPECT_TRUE(res["ok"].as<bool>()) << run << ": " << res["error"].as<std::string>() << "\n"
                                      << (fs::exists(rd + "/run.err") ? slurp(rd + "/run.err") : std::string("(no run.err)"));
    EXPECT_EQ(res["transport"].as<std::string>(), "dds");
    hosts.insert(res["host"].as<std::string>());
    where += std::string(run) + " on '" + res["host"].as<std::string>() + "' " + res["wall_s"].as<std::string>() + " s; ";
  }
  EXPECT_EQ(hosts, (std::set<std::string>{a, b})) << where << "\n" << r.out << r.err;
  if (!HasFailure()) fs::remove_all(dir);
}
