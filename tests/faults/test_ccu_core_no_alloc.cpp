// The CCU's per-sample and per-period path allocates nothing: CcuCore (ccu/process/ccu_core.hpp,
// the CCU process without DDS: four CornerSupervisors, fusion, the command plan with the
// Redistributor) fed by four simulated corners over a run in which FL's load-cell bias is
// detected and reacted to. Counted with a replaced operator new (tests/support/alloc_counter).
#include <gtest/gtest.h>

#include <array>
#include <memory>

#include "alloc_counter.hpp"
#include "bbw/faults/injector.hpp"
#include "bbw/scenario/corner_sim.hpp"
#include "bbw/node/ccu_core.hpp"
#include "closed_loop.hpp"

using namespace bbw;

TEST(CcuCoreAllocation, NoHeapAllocationPerSampleOrPeriod) {
  auto fs = faults::load_fault_scenario(faults::test::source_path("config/scenarios/faults/load_cell_bias.yaml"));
  const auto options = faults::test::default_options();
  ccu::CcuCore core(fs.scenario, options.calibrator);
  std::array<std::unique_ptr<scenario::CornerSim>, 4> sims;
  std::array<std::unique_ptr<faults::FaultInjector>, 4> injectors;
  for (std::size_t i = 0; i < 4; ++i) {
    sims[i] = std::make_unique<scenario::CornerSim>(fs.scenario, core.scenario_index(i));
    injectors[i] = std::make_unique<faults::FaultInjector>(fs.faults, static_cast<faults::Target>(i), 7);
  }
  const double dt = fs.scenario.plant_dt_s;
  bbw::msg::MeasurementSample wire;  // the wire sample, reused
  const long before = test::allocation_count();
  double fused_sum = 0.0, command_sum = 0.0;
  for (int k = 0; k < 2800; ++k) {  // 14 s of 5 ms periods
    const double t0 = k * fs.scenario.ccu_period_s;
    const auto& plan = core.plan(t0);
    for (std::size_t i = 0; i < 4; ++i) {
      scenario::ExternalInputs ext;
      ext.force_command_kN = plan[i].clamp_force_kN;
      ext.feedback = plan[i].feedback;
      if (plan[i].feedback) ext.curve = scenario::CurveEstimate{plan[i].curve.a, plan[i].curve.b, plan[i].curve.c, plan[i].curve.d};
      command_sum += plan[i].clamp_force_kN;
      for (int s = 0; s < 5; ++s) {
        injectors[i]->prepare(ext, sims[i]->time_s() + dt);
        const auto& smp = sims[i]->step(dt, ext);
        const faults::CornerReading r = faults::test::reading_from(smp, wire);
        const ccu::SampleOutcome& o = core.on_sample(i, r, t0 + fs.scenario.ccu_period_s);
        if (o.valid) fused_sum += o.fused_kN;
      }
    }
    core.tick(t0 + fs.scenario.ccu_period_s);
  }
  EXPECT_EQ(test::allocation_count() - before, 0);
  EXPECT_GT(fused_sum, 0.0);
  EXPECT_GT(command_sum, 0.0);
  EXPECT_GT(core.supervisor(0).calibrator().stats().fits_accepted, 0u);
  EXPECT_FALSE(core.supervisor(0).monitor().ok(faults::Part::LoadCell));  // the bias at 11 s was found
  EXPECT_EQ(core.supervisor(0).view().feedback, corner_unit::ForceFeedback::Curve);  // and reacted to
}
