// Lockstep real-time factor of the node cores over the in-memory transport (one process, one
// thread): config/scenarios/four_corner_rig.yaml (four 1 kHz corners, 5 ms CCU period, 20 s
// simulated). BM_InProcessFourCornerRig: no logs (the nodes and the transport only);
// BM_InProcessFourCornerRigLogged: with the CCU's and corners' CSV logs (the observers bbw_inproc
// and the processes use) into a temporary folder. Counter real_time_factor = simulated / wall.
// Compare with bench_dds_lockstep (the same scenario as five processes over Fast DDS) in one run:
// docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/node/csv_log.hpp"
#include "bbw/node/in_process.hpp"

namespace {

void in_process_rig(benchmark::State& state, bool logged) {
  const auto fs = bbw::faults::load_fault_scenario(std::string(BBW_SOURCE_DIR) + "/config/scenarios/four_corner_rig.yaml");
  const auto calibrator = bbw::calibration::load_config(std::string(BBW_SOURCE_DIR) + "/config/calibrator/robust.yaml");
  const std::string dir = (std::filesystem::temp_directory_path() / "bbw_bench_in_process").string();
  std::filesystem::create_directories(dir);
  double sim_s = 0.0, wall_s = 0.0;
  for (auto _ : state) {
    bbw::node::InProcessOptions options;
    options.schedule = fs.faults;
    bbw::node::InProcessRun run(fs.scenario, calibrator, options);
    std::unique_ptr<bbw::node::CcuCsvLog> ccu_log;
    std::vector<std::unique_ptr<bbw::node::CornerPeriodsLog>> corner_logs;
    if (logged) {
      ccu_log = std::make_unique<bbw::node::CcuCsvLog>(dir, run.ccu());
      run.ccu().set_observer(ccu_log.get());
      for (std::size_t i = 0; i < run.corners(); ++i) {
        corner_logs.push_back(std::make_unique<bbw::node::CornerPeriodsLog>(
            dir + "/corner_" + bbw::corner_name(run.corner(i).corner()) + "_periods.csv", 0));
        run.corner(i).set_observer(corner_logs.back().get());
      }
    }
    const auto t0 = std::chrono::steady_clock::now();
    run.run();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    run.ccu().set_observer(nullptr);
    state.SetIterationTime(wall);
    wall_s += wall;
    sim_s += static_cast<double>(run.periods_done()) * fs.scenario.ccu_period_s;
  }
  state.counters["real_time_factor"] = wall_s > 0.0 ? sim_s / wall_s : 0.0;
}

void BM_InProcessFourCornerRig(benchmark::State& state) { in_process_rig(state, false); }
void BM_InProcessFourCornerRigLogged(benchmark::State& state) { in_process_rig(state, true); }

BENCHMARK(BM_InProcessFourCornerRig)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_InProcessFourCornerRigLogged)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
