#include <gtest/gtest.h>

#include <cmath>

#include "bbw/plant/plant.hpp"
#include "rig.hpp"

using namespace bbw;

TEST(Plant, CurrentFollowsTheCommandWithTheRLTimeConstant) {
  plant::PlantParams p;
  p.sensors.current_noise_A = 0.0;
  plant::Plant pl(p, {}, {}, 1);
  pl.reset(0.0);
  const double tau_s = p.motor.inductance_H / p.motor.resistance_Ohm;
  double t = 0.0;
  const double dt = tau_s / 20.0;
  while (t < tau_s - 1e-12) {
    pl.step({10.0}, dt);
    t += dt;
  }
  EXPECT_NEAR(pl.state().current_A, 10.0 * (1.0 - std::exp(-1.0)), 0.05);
  for (int i = 0; i < 500; ++i) pl.step({1000.0}, dt);
  EXPECT_NEAR(pl.state().current_A, p.motor.current_limit_A, 1e-6);  // clipped
}

TEST(Plant, StaticTorqueBalanceAtTheHoldingCurrent) {
  plant::PlantParams p;
  plant::Plant pl(p, {}, {}, 2);
  pl.reset(1.0);
  const double target_kN = 20.0;
  // Open loop the spindle rings (about 0.7 Hz) and settles within a few seconds.
  for (int i = 0; i < 8000; ++i) pl.step({pl.holding_current_A(target_kN)}, 1e-3);
  // Drive friction (coulomb_friction_Nm) and key friction can hold it off the exact balance.
  const double friction_kN = p.transmission.coulomb_friction_Nm / (1000 * p.transmission.lead_mm_per_rev * 1e-3 / 6.283185307179586) +
                             p.key_friction.half_width_kN;
  EXPECT_NEAR(pl.state().force_true_kN, target_kN, friction_kN + 0.1);
  EXPECT_NEAR(pl.state().speed_rev_per_s, 0.0, 1e-3);
}

TEST(Plant, SensorsAreNoisyReproducibleAndQuantised) {
  plant::PlantParams p;
  auto run = [&](std::uint64_t seed) {
    plant::Plant pl(p, {}, {}, seed);
    pl.reset(2.0);
    std::vector<double> v;
    for (int i = 0; i < 2000; ++i) {
      const auto& m = pl.step({pl.holding_current_A(pl.state().force_true_kN)}, 1e-3);
      v.push_back(m.force_internal_kN - pl.state().force_true_kN - pl.state().friction_kN);
      const double q = pl.resolver_quantum_rev();
      EXPECT_NEAR(m.position_rev / q, std::round(m.position_rev / q), 1e-6);
    }
    return v;
  };
  const auto a = run(9), b = run(9), c = run(10);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  double ss = 0.0;
  for (const double e : a) ss += e * e;
  EXPECT_NEAR(std::sqrt(ss / a.size()), p.sensors.load_cell_noise_kN, 0.003);
}

// A drive without torque, back-driven by a 30 kN clamp load: the spindle spins back, past the
// released home, and stops at the retracted end stop; without the stop it ran on for tens of
// revolutions (tuning seed 1401 run 81: -42 rev).
TEST(Plant, ABackDrivenRotorStopsAtTheRetractedEndStop) {
  plant::PlantParams p;
  plant::Plant pl(p, {}, {}, 3);
  pl.reset(6.0);
  ASSERT_GT(pl.state().force_true_kN, 20.0);
  double min_rev = 1e9, speed_at_min = 0.0;
  for (int i = 0; i < 3000; ++i) {
    pl.step({40.0, 0.0}, 1e-3);  // full current, no torque (a total loss)
    if (pl.state().motor_position_rev < min_rev) {
      min_rev = pl.state().motor_position_rev;
      speed_at_min = pl.state().speed_rev_per_s;
    }
  }
  // It reached the stop and never went past it; from there only the keys' friction moves it.
  EXPECT_GE(min_rev, p.transmission.retracted_stop_rev);
  EXPECT_NEAR(min_rev, p.transmission.retracted_stop_rev, 1e-4);
  EXPECT_GE(speed_at_min, 0.0);
  EXPECT_GE(pl.state().motor_position_rev, p.transmission.retracted_stop_rev);
  EXPECT_LT(pl.state().motor_position_rev, 0.0);
  EXPECT_LT(pl.state().force_true_kN, 0.01);
  p.transmission.retracted_stop_rev = 0.1;  // beyond the released home
  EXPECT_THROW(plant::Plant(p, {}, {}, 1), std::invalid_argument);
}

TEST(Plant, RejectsInvalidParameters) {
  plant::PlantParams p;
  p.transmission.gear_ratio = 0.0;
  EXPECT_THROW(plant::Plant(p, {}, {}, 1), std::invalid_argument);
  p = {};
  plant::EffectsParams e;
  e.creep.time_constant_s = -1.0;
  EXPECT_THROW(plant::Plant(p, e, {}, 1), std::invalid_argument);
  plant::Conditions c;
  c.wear_rate_rev_per_kN_s = -1.0;
  EXPECT_THROW(plant::Plant(p, {}, c, 1), std::invalid_argument);
}

TEST(Plant, WearMovesTheContactPointWithClampWork) {
  // Hold 5 rev for 10 s; the contact point moves by rate * integral of F dt, so the force
  // at the held position falls.
  scenario::PositionProfileSpec prof;
  prof.segments.push_back(scenario::Hold{5.0, 10.0});
  auto s = test::rig(prof, 40.0, {}, 11.0);
  s.corners[0].conditions.wear_rate_rev_per_kN_s = 1e-4;
  scenario::CornerSim sim(s, 0);
  double integral_kN_s = 0.0;
  double f_start = 0.0;
  for (int i = 0; i < 11000; ++i) {
    const auto& x = sim.step(1e-3);
    integral_kN_s += x.force_true_kN * 1e-3;
    if (i == 1500) f_start = x.force_true_kN;
  }
  EXPECT_NEAR(sim.plant().state().wear_rev, 1e-4 * integral_kN_s, 1e-3 * 1e-4 * integral_kN_s + 1e-9);
  EXPECT_GT(sim.plant().state().wear_rev, 0.02);
  EXPECT_LT(sim.plant().state().force_true_kN, f_start - 0.1);
  const auto& pl = sim.plant();
  EXPECT_NEAR(pl.curve().contact_rev(40.0, pl.state().wear_rev) - pl.curve().contact_rev(40.0, 0.0),
              pl.state().wear_rev, 1e-12);
}
