// step() of the plant, the controller and CornerSim must not allocate: count every global
// operator new while stepping with all effects on.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "rig.hpp"

namespace {
std::atomic<long> g_allocations{0};
}

void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

using namespace bbw;

TEST(Allocation, CounterSeesAllocations) {
  const long before = g_allocations.load();
  auto* v = new std::vector<double>(100);
  delete v;
  EXPECT_GE(g_allocations.load() - before, 2);
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
  const long before = g_allocations.load();
  for (int i = 0; i < 6000; ++i) {
    sink += pos.step(1e-3).force_internal_kN;
    sink += force.step(1e-3, ext).force_internal_kN;
    if (i == 3000) ext.force_command_kN = 12.0;
  }
  const long after = g_allocations.load();
  EXPECT_EQ(after - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
}
