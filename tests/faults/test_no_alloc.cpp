// Per-sample fault code allocates nothing after construction: the injector on a CornerSim, the
// corner watchdog, and the CCU's CornerSupervisor (guard, calibrator, monitor, reactions) and
// Redistributor, over a run with a load-cell fault being detected and reacted to.
#include <gtest/gtest.h>

#include "alloc_counter.hpp"

#include <cstdlib>

#include "bbw/faults/ccu_watchdog.hpp"
#include "bbw/faults/corner_supervisor.hpp"
#include "bbw/faults/injector.hpp"
#include "bbw/faults/redistributor.hpp"
#include "closed_loop.hpp"


using namespace bbw::faults;

TEST(FaultAllocation, NoHeapAllocationPerSample) {
  auto fs = load_fault_scenario(test::source_path("config/scenarios/faults/load_cell_bias.yaml"));
  // A constant command gives the calibrator no cycles: use a bias above the uncalibrated threshold.
  fs.faults.faults.at(0).bias_kN = 4.0;
  const auto options = test::default_options();
  bbw::scenario::CornerSim sim(fs.scenario, 0);
  FaultInjector injector(fs.faults, Target::FL, 5);
  CcuWatchdog watchdog(options.watchdog);
  CornerSupervisor sup(options.calibrator, options.monitor, Target::FL);
  const Redistributor redistributor(0.6);
  std::array<CornerCapacity, kCorners> cap{};
  bbw::msg::MeasurementSample wire;  // the wire sample, reused
  const long before = bbw::test::allocation_count();
  double sum = 0.0;
  for (int k = 0; k < 14000; ++k) {
    const double t = sim.time_s() + 0.001;
    watchdog.on_command(t, 20.0);
    bbw::scenario::ExternalInputs ext;
    ext.force_command_kN = watchdog.at(t).force_command_kN;
    ext.feedback = sup.view().feedback;
    injector.prepare(ext, t);
    const auto& s = sim.step(0.001, ext);
    const CornerReading r = test::reading_from(s, wire);
    const CornerView& v = sup.on_sample(r, t);
    sup.tick(t);
    cap[0] = {v.available, v.force_limit_kN};
    sum += redistributor.allocate(66.0, cap).total_kN;
  }
  EXPECT_EQ(bbw::test::allocation_count() - before, 0);
  EXPECT_GT(sum, 0.0);
  EXPECT_FALSE(sup.monitor().ok(Part::LoadCell));  // the bias at 11 s was found and reacted to
}
