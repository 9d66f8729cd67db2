// The DDS processes (bbw_launch -> bbw_ccu + four bbw_corner, lockstep) write the logs pinned in
// tests/node/data/lockstep_digests.txt, which the in-process runner (NodeDigests.*) writes too:
// behaviour unchanged by the node-core redesign, and the in-memory transport and Fast DDS run one
// protocol. Domains 140, 141, 146.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "system_test_support.hpp"

namespace {

using namespace std::chrono_literals;
using namespace bbw::system_test;

std::string sha256_of(const std::string& file) {
  std::FILE* p = ::popen(("sha256sum '" + file + "'").c_str(), "r");
  if (p == nullptr) return "";
  std::array<char, 65> hex{};
  const std::size_t n = std::fread(hex.data(), 1, 64, p);
  ::pclose(p);
  return n == 64 ? std::string(hex.data(), 64) : "";
}

std::map<std::string, std::string> pinned(const std::string& scenario) {
  std::ifstream in(src("tests/node/data/lockstep_digests.txt"));
  std::map<std::string, std::string> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::string sc, file, digest;
    s >> sc >> file >> digest;
    if (sc == scenario) out[file] = digest;
  }
  return out;
}

void expect_pinned_logs(const std::string& scenario, int domain, const std::string& test,
                        const std::vector<std::string>& env = {}) {
  const std::string dir = scratch("equivalence", test);
  const ProcessRun r = run("bbw_launch",
                           {bin("bbw_launch"), src(scenario), "--out", dir + "/out", "--mode", "lockstep", "--domain",
                            std::to_string(domain), "--discovery-timeout", "20", "--no-report"},
                           dir, 150s, env);
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.out << r.err;
  const auto digests = pinned(scenario);
  ASSERT_GE(digests.size(), 9u) << scenario << ": no pinned digests";
  for (const auto& [file, digest] : digests) {
    EXPECT_EQ(sha256_of(dir + "/out/" + file), digest) << scenario << ": " << file << " differs from the pinned log";
  }
  std::filesystem::remove_all(dir);
}

// Domain 140.
TEST(SystemNodeEquivalence, VehicleStopLogsEqualThePinnedLogs) {
  expect_pinned_logs("config/scenarios/vehicle_stop.yaml", 140, "vehicle_stop");
}

// Domain 146: the same logs with the lockstep periods run on the processes' main threads
// (BBW_LOCKSTEP_ON_RECEIVE=0) instead of the Fast DDS threads that receive their grant and their
// last block (the default; docs/benchmarks.md): the two loops are one protocol.
TEST(SystemNodeEquivalence, PeriodsOnTheMainThreadWriteTheSameLogs) {
  expect_pinned_logs("config/scenarios/vehicle_stop.yaml", 146, "main_thread", {"BBW_LOCKSTEP_ON_RECEIVE=0"});
}

// Domain 141: a network fault (silence, then the corner's return) crosses the adapters' link events.
TEST(SystemNodeEquivalence, NetworkSilenceLogsEqualThePinnedLogs) {
  expect_pinned_logs("config/scenarios/faults/network_silence.yaml", 141, "network_silence");
}

}  // namespace
