// Lockstep real-time factor: bbw_launch runs config/scenarios/four_corner_rig.yaml (four 1 kHz
// corners, 5 ms CCU period, 20 s simulated) as five processes over the default transport.
// Manual time = the CCU's wall time from the first command to the last block; counters:
// real_time_factor = simulated / wall, and the CCU's and corners' CPU seconds are in the logs.
// BM_LockstepFourCornerRigSecure: the same with ./bbw run --secure (keys from env
// BBW_BENCH_KEYS, default keys/ in the repository; the launcher creates them if missing).
// Domain: env BBW_BENCH_DOMAIN (default 202).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "bbw/runtime/child.hpp"
#include "bbw/runtime/stats_file.hpp"

namespace {

using namespace std::chrono_literals;

void lockstep_rig(benchmark::State& state, bool secure) {
  const char* env = std::getenv("BBW_BENCH_DOMAIN");
  const std::string domain = env ? env : "202";
  const std::string out = (std::filesystem::temp_directory_path() / "bbw_bench_lockstep").string();
  const std::string stats = out + "/out/ccu.stats";
  double rtf_sum = 0.0;
  double rtf_min = 1e9;
  int runs = 0;
  for (auto _ : state) {
    std::filesystem::remove_all(out);
    std::filesystem::create_directories(out);
    std::vector<std::string> argv{bbw::runtime::executable_dir() + "/bbw_launch",
                                  std::string(BBW_SOURCE_DIR) + "/config/scenarios/four_corner_rig.yaml", "--out",
                                  out + "/out", "--mode", "lockstep", "--domain", domain, "--no-report"};
    if (secure) {
      const char* keys = std::getenv("BBW_BENCH_KEYS");
      argv.insert(argv.end(), {"--secure", "--keys", keys && *keys ? keys : std::string(BBW_SOURCE_DIR) + "/keys"});
    }
    bbw::runtime::Child launch("bbw_launch", argv, out + "/launch.out", out + "/launch.err");
    const auto status = launch.wait_until(std::chrono::steady_clock::now() + 300s);
    if (!status || !status->ok()) {
      state.SkipWithError("bbw_launch failed; see /tmp/bbw_bench_lockstep/launch.err");
      return;
    }
    const auto s = bbw::runtime::read_stats(stats);
    const double wall = bbw::runtime::stat_number(s, "wall_s", stats);
    const double sim = bbw::runtime::stat_number(s, "sim_s", stats);
    state.SetIterationTime(wall);
    rtf_sum += sim / wall;
    rtf_min = std::min(rtf_min, sim / wall);
    ++runs;
  }
  if (runs > 0) {
    state.counters["real_time_factor_mean"] = rtf_sum / runs;
    state.counters["real_time_factor_min"] = rtf_min;
  }
}

void BM_LockstepFourCornerRig(benchmark::State& state) { lockstep_rig(state, false); }
void BM_LockstepFourCornerRigSecure(benchmark::State& state) { lockstep_rig(state, true); }

}  // namespace

BENCHMARK(BM_LockstepFourCornerRigSecure)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(3);
BENCHMARK(BM_LockstepFourCornerRig)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(3);
