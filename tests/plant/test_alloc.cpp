// step() of the plant, the controller and CornerSim must not allocate: count every global
// operator new while stepping with all effects on.
#include <gtest/gtest.h>

#include "alloc_counter.hpp"

#include <cstdlib>

#include "rig.hpp"


using namespace bbw;

TEST(Allocation, CounterSeesAllocations) {
  const long before = bbw::test::allocation_count();
  // Explicit calls: a new-expression's allocation may be elided by the compiler.
  void* a = ::operator new(64);
  void* b = ::operator new[](64);
  ::operator delete(a);
  ::operator delete[](b);
  EXPECT_EQ(bbw::test::allocation_count() - before, 2);
}

TEST(Allocation, CornerSimStepIsAllocationFreeWithEveryEffectOn) {
  plant::EffectsParams e;
  e.viscous_friction.enabled = true;
  e.load_dependent_friction.enabled = true;
  e.sensor_delay.enabled = true;
  e.sensor_delay.delay_s = 0.01;
  e.thermal_drift.enabled = true;
  e.backlash.enabled = true;
  e.creep.enabled = true;
  auto s = test::rig(test::sweep_profile(), 40.0, e, 6.0);
  scenario::CornerSim pos(s, 0);
  s.corners[0].drive.mode = scenario::DriveMode::Force;
  s.corners[0].drive.force_kN = {{0.0, 0.0}, {1.0, 20.0}, {3.0, 5.0}};
  s.corners[0].drive.feedback = corner_unit::ForceFeedback::Compensated;
  scenario::CornerSim force(s, 0);
  scenario::ExternalInputs ext;
  ext.friction_estimate_kN = 0.3;
  ext.curve = scenario::CurveEstimate{0.1, 0.2, 1.0, 0.0};
  double sink = 0.0;
  const long before = bbw::test::allocation_count();
  for (int i = 0; i < 6000; ++i) {
    sink += pos.step(1e-3).force_internal_kN;
    sink += force.step(1e-3, ext).force_internal_kN;
    if (i == 3000) ext.force_command_kN = 12.0;
  }
  const long after = bbw::test::allocation_count();
  EXPECT_EQ(after - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
}
