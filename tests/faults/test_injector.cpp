// FaultInjector: each sensor fault on the readings, actuator faults through the plant, and the
// CornerSim hooks (readings seen by sample and controller, torque scale).
#include <gtest/gtest.h>

#include <cmath>

#include "bbw/faults/injector.hpp"
#include "closed_loop.hpp"

using namespace bbw::faults;

namespace {

FaultSchedule one(FaultSpec f) {
  FaultSchedule s;
  s.faults.push_back(f);
  return s;
}

FaultSpec spec(FaultType type, Part part, double at_s, double duration_s = -1.0) {
  FaultSpec f;
  f.at_s = at_s;
  f.target = Target::FL;
  f.part = part;
  f.type = type;
  if (duration_s > 0.0) f.duration_s = duration_s;
  return f;
}

bbw::plant::Measurement reading(double t, double x, double lc) {
  bbw::plant::Measurement m;
  m.time_s = t;
  m.position_rev = x;
  m.speed_rev_per_s = 1.0;
  m.force_internal_kN = lc;
  return m;
}

}  // namespace

TEST(FaultInjector, LoadCellFaultsChangeOnlyTheLoadCellAndOnlyWhileActive) {
  auto f = spec(FaultType::Bias, Part::LoadCell, 1.0, 0.5);
  f.bias_kN = 1.25;
  FaultInjector bias(one(f), Target::FL, 1);
  auto m = reading(0.999, 2.0, 5.0);
  bias.apply(m);
  EXPECT_DOUBLE_EQ(m.force_internal_kN, 5.0);
  m = reading(1.2, 2.0, 5.0);
  bias.apply(m);
  EXPECT_DOUBLE_EQ(m.force_internal_kN, 6.25);
  EXPECT_DOUBLE_EQ(m.position_rev, 2.0);
  m = reading(1.5, 2.0, 5.0);
  bias.apply(m);
  EXPECT_DOUBLE_EQ(m.force_internal_kN, 5.0);

  auto d = spec(FaultType::Drift, Part::LoadCell, 1.0);
  d.rate_kN_per_s = -2.0;
  FaultInjector drift(one(d), Target::FL, 1);
  m = reading(1.25, 2.0, 5.0);
  drift.apply(m);
  EXPECT_DOUBLE_EQ(m.force_internal_kN, 4.5);

  FaultInjector dropout(one(spec(FaultType::Dropout, Part::LoadCell, 1.0)), Target::FL, 1);
  m = reading(1.0, 2.0, 5.0);
  dropout.apply(m);
  EXPECT_TRUE(std::isnan(m.force_internal_kN));
  EXPECT_DOUBLE_EQ(m.position_rev, 2.0);

  FaultInjector stuck(one(spec(FaultType::Stuck, Part::LoadCell, 1.0)), Target::FL, 1);
  m = reading(0.999, 2.0, 7.0);
  stuck.apply(m);
  for (double t : {1.0, 1.1, 1.2}) {
    m = reading(t, 2.0 + t, 7.0 + 3.0 * t);
    stuck.apply(m);
    EXPECT_DOUBLE_EQ(m.force_internal_kN, 7.0);  // the value delivered before the fault
    EXPECT_DOUBLE_EQ(m.position_rev, 2.0 + t);
  }

  auto n = spec(FaultType::NoiseBurst, Part::LoadCell, 0.0);
  n.rms_kN = 0.5;
  FaultInjector noise(one(n), Target::FL, 7);
  double sum2 = 0.0;
  for (int k = 0; k < 4000; ++k) {
    m = reading(0.001 * k, 2.0, 5.0);
    noise.apply(m);
    sum2 += (m.force_internal_kN - 5.0) * (m.force_internal_kN - 5.0);
  }
  EXPECT_NEAR(std::sqrt(sum2 / 4000), 0.5, 0.03);
}

TEST(FaultInjector, ResolverFaultsChangeOnlyThePosition) {
  auto o = spec(FaultType::Offset, Part::Resolver, 1.0);
  o.offset_rev = 0.2;
  FaultInjector offset(one(o), Target::FL, 1);
  auto m = reading(1.0, 2.0, 5.0);
  offset.apply(m);
  EXPECT_DOUBLE_EQ(m.position_rev, 2.2);
  EXPECT_DOUBLE_EQ(m.force_internal_kN, 5.0);

  FaultInjector stuck(one(spec(FaultType::Stuck, Part::Resolver, 1.0)), Target::FL, 1);
  m = reading(0.999, 3.0, 5.0);
  m.speed_rev_per_s = 0.7;
  stuck.apply(m);
  m = reading(1.3, 4.0, 9.0);
  stuck.apply(m);
  EXPECT_DOUBLE_EQ(m.position_rev, 3.0);
  EXPECT_DOUBLE_EQ(m.speed_rev_per_s, 0.7);
  EXPECT_DOUBLE_EQ(m.force_internal_kN, 9.0);
}

TEST(FaultInjector, ActuatorFaultsScaleTheTorqueAndOtherCornersAreUntouched) {
  auto p = spec(FaultType::TorqueLoss, Part::Actuator, 1.0, 1.0);
  p.torque_loss_percent = 60.0;
  FaultSchedule s = one(p);
  s.faults.push_back(spec(FaultType::TotalLoss, Part::Actuator, 3.0));
  FaultInjector inj(s, Target::FL, 1);
  EXPECT_DOUBLE_EQ(inj.torque_scale(0.5), 1.0);
  EXPECT_DOUBLE_EQ(inj.torque_scale(1.5), 0.4);
  EXPECT_DOUBLE_EQ(inj.torque_scale(2.5), 1.0);
  EXPECT_DOUBLE_EQ(inj.torque_scale(3.5), 0.0);
  FaultInjector other(s, Target::RR, 1);
  EXPECT_TRUE(other.faults().empty());
  EXPECT_THROW(FaultInjector(s, Target::CCU, 1), std::invalid_argument);
}

TEST(FaultInjector, InCornerSimTheBiasReachesSampleAndLoopAndTotalLossReleasesTheBrake) {
  const auto fs = load_fault_scenario(test::source_path("config/scenarios/faults/fault_free_stop.yaml"));
  auto f = spec(FaultType::Bias, Part::LoadCell, 7.0);
  f.bias_kN = 2.0;
  FaultInjector inj(one(f), Target::FL, 3);
  // The actuator test in holds off: its pulses, every 0.15 s from where each hold began, move
  // the key friction for a few ms, and the healthy and the faulty corner's holds begin apart.
  auto scenario = fs.scenario;
  scenario.controller.hold_test_current_A = 0.0;
  bbw::scenario::CornerSim healthy(scenario, 0), faulty(scenario, 0);
  for (int k = 0; k < 7500; ++k) {
    bbw::scenario::ExternalInputs ext;
    ext.force_command_kN = 20.0;
    bbw::scenario::ExternalInputs ext_f = ext;
    inj.prepare(ext_f, faulty.time_s() + 0.001);
    const auto& a = healthy.step(0.001, ext);
    const auto& b = faulty.step(0.001, ext_f);
    if (b.time_s < 7.0 - 1e-9) {
      ASSERT_DOUBLE_EQ(a.force_internal_kN, b.force_internal_kN) << b.time_s;
    }
  }
  // The local loop follows the biased load cell: the true force ends lower by the bias, give
  // or take the key friction, which changes sign as the actuator backs off.
  const double friction_shift = faulty.last().friction_true_kN - healthy.last().friction_true_kN;
  EXPECT_NEAR(healthy.last().force_true_kN - faulty.last().force_true_kN, 2.0 + friction_shift, 0.15);
  EXPECT_GT(healthy.last().force_true_kN - faulty.last().force_true_kN, 0.5);
  EXPECT_NEAR(faulty.last().force_internal_kN - healthy.last().force_internal_kN, 0.0, 0.2);

  FaultInjector dead(one(spec(FaultType::TotalLoss, Part::Actuator, 1.0)), Target::FL, 3);
  bbw::scenario::CornerSim sim(fs.scenario, 0);
  double at_1s = 0.0;
  for (int k = 0; k < 2000; ++k) {
    bbw::scenario::ExternalInputs ext;
    ext.force_command_kN = 20.0;
    dead.prepare(ext, sim.time_s() + 0.001);
    sim.step(0.001, ext);
    if (k == 999) at_1s = sim.last().force_true_kN;
  }
  EXPECT_GT(at_1s, 18.0);
  EXPECT_LT(sim.last().force_true_kN, 2.0);
  EXPECT_GT(std::abs(sim.last().motor_current_A), 30.0);  // current flows, no torque
}

// A seized actuator: told to release after 1 s, the brake keeps its force and its position while
// the motor pulls back at its current limit; a healthy one releases.
TEST(FaultInjector, ASeizedActuatorHoldsItsForceWhenToldToRelease) {
  const auto fs = load_fault_scenario(test::source_path("config/scenarios/faults/fault_free_stop.yaml"));
  FaultInjector jam(one(spec(FaultType::Seized, Part::Actuator, 1.0)), Target::FL, 3);
  EXPECT_FALSE(jam.seized(0.999));
  EXPECT_TRUE(jam.seized(1.0));
  EXPECT_DOUBLE_EQ(jam.torque_scale(1.5), 1.0);
  bbw::scenario::CornerSim sim(fs.scenario, 0), healthy(fs.scenario, 0);
  double force_at_1s = 0.0, position_at_1s = 0.0;
  for (int k = 0; k < 2000; ++k) {
    bbw::scenario::ExternalInputs ext;
    ext.force_command_kN = k < 1000 ? 20.0 : 0.0;
    bbw::scenario::ExternalInputs ext_h = ext;
    jam.prepare(ext, sim.time_s() + 0.001);
    sim.step(0.001, ext);
    healthy.step(0.001, ext_h);
    if (k == 999) {
      force_at_1s = sim.last().force_true_kN;
      position_at_1s = sim.plant().state().position_rev;
    }
  }
  EXPECT_GT(force_at_1s, 18.0);
  EXPECT_NEAR(sim.last().force_true_kN, force_at_1s, 0.5);  // only creep, if on, could move it
  EXPECT_DOUBLE_EQ(sim.plant().state().position_rev, position_at_1s);
  EXPECT_LT(sim.last().motor_current_A, -10.0);  // the motor pulls back, nothing moves
  EXPECT_LT(healthy.last().force_true_kN, 1.0);
}

TEST(FaultInjector, ADropoutReachesTheSampleWhileTheLocalLoopHoldsItsLastValue) {
  const auto fs = load_fault_scenario(test::source_path("config/scenarios/faults/fault_free_stop.yaml"));
  FaultInjector inj(one(spec(FaultType::Dropout, Part::LoadCell, 1.0, 0.2)), Target::FL, 3);
  bbw::scenario::CornerSim sim(fs.scenario, 0);
  int nan_samples = 0;
  for (int k = 0; k < 1500; ++k) {
    bbw::scenario::ExternalInputs ext;
    ext.force_command_kN = 15.0;
    inj.prepare(ext, sim.time_s() + 0.001);
    const auto& s = sim.step(0.001, ext);
    nan_samples += std::isnan(s.force_internal_kN) ? 1 : 0;
    ASSERT_TRUE(std::isfinite(s.force_true_kN)) << s.time_s;
  }
  EXPECT_EQ(nan_samples, 200);
  EXPECT_NEAR(sim.last().force_true_kN, 15.0, 1.5);
}
