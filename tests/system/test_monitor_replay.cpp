// bbw_monitor_replay (tools/monitor_replay): a corner's CCU log replayed through a fresh
// CornerSupervisor gives the run's own friction, curve and fused estimate (it is exact up to the
// first finding; this run raises none), and bad input is refused with its reason.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "system_test_support.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using bbw::system_test::bin;
using bbw::system_test::src;

namespace {

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string f;
  while (std::getline(ss, f, sep)) out.push_back(f);
  return out;
}

}  // namespace

TEST(MonitorReplay, ReplaysTheRunsOwnEstimatesSampleBySample) {
  const std::string dir = bbw::system_test::scratch("replay", "rig");
  const std::string scenario = src("config/scenarios/four_corner_rig.yaml");
  const auto run = bbw::system_test::run("inproc", {bin("bbw_inproc"), scenario, "--out", dir + "/out"}, dir, 60s);
  ASSERT_TRUE(run.status.ok()) << run.err;
  const auto replay = bbw::system_test::run("replay", {bin("bbw_monitor_replay"), scenario, dir + "/out/ccu_FL.csv", "FL"}, dir, 60s);
  ASSERT_TRUE(replay.status.ok()) << replay.err;
  // The log's friction, curve and fused estimate by time (printed to 3 decimals by the replay).
  std::ifstream log(dir + "/out/ccu_FL.csv");
  std::string line;
  std::getline(log, line);
  std::map<std::string, std::size_t> col;
  for (const auto& h : split(line, ',')) col.emplace(h, col.size());
  std::map<long, std::vector<double>> by_ms;
  while (std::getline(log, line)) {
    const auto f = split(line, ',');
    by_ms[std::lround(std::stod(f[col.at("time_s")]) * 1000.0)] = {std::stod(f[col.at("friction_kN")]),
                                                                   std::stod(f[col.at("curve_kN")]),
                                                                   std::stod(f[col.at("fused_kN")])};
  }
  std::stringstream out(replay.out);
  std::getline(out, line);  // # half_width_kN
  std::getline(out, line);  // column names
  const auto names = split(line, ' ');
  ASSERT_GE(names.size(), 9u);
  ASSERT_EQ(names[6], "fric");
  ASSERT_EQ(names[7], "est");
  ASSERT_EQ(names[8], "curve");
  std::size_t compared = 0;
  while (std::getline(out, line)) {
    const auto f = split(line, ' ');
    ASSERT_GE(f.size(), 9u) << line;
    const auto it = by_ms.find(std::lround(std::stod(f[0]) * 1000.0));
    ASSERT_NE(it, by_ms.end()) << line;
    if (!std::isfinite(it->second[0])) continue;  // no estimate logged for this sample
    EXPECT_NEAR(std::stod(f[6]), it->second[0], 6e-4) << line;
    EXPECT_NEAR(std::stod(f[8]), it->second[1], 6e-4) << line;
    EXPECT_NEAR(std::stod(f[7]), it->second[2], 6e-4) << line;
    ++compared;
  }
  EXPECT_GT(compared, 10000u);
  if (!HasFailure()) fs::remove_all(dir);
}

TEST(MonitorReplay, BadInputIsRefusedWithItsReason) {
  const std::string dir = bbw::system_test::scratch("replay", "bad");
  const std::string scenario = src("config/scenarios/four_corner_rig.yaml");
  std::ofstream(dir + "/short.csv") << "time_s,seq\n0.001,1\n";
  const struct {
    std::vector<std::string> args;
    int code;
    std::string message;
  } cases[] = {
      {{scenario}, 2, "are required"},
      {{scenario, dir + "/short.csv", "XX"}, 2, "CORNER must be FL, FR, RL or RR, got 'XX'"},
      {{scenario, dir + "/short.csv", "FL", "--every"}, 2, "--every needs a value"},
      {{scenario, dir + "/short.csv", "FL", "--bogus", "1"}, 2, "unknown argument '--bogus'"},
      {{scenario, dir + "/short.csv", "FL"}, 2, "short.csv:1: no column 'position_rev'"},
      {{scenario, dir + "/missing.csv", "FL"}, 1, "missing.csv: cannot read"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> argv{bin("bbw_monitor_replay")};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    const auto r = bbw::system_test::run("replay", argv, dir, 60s);
    EXPECT_EQ(r.status.code, c.code) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
  }
  if (!HasFailure()) fs::remove_all(dir);
}
