// The vehicle plant against closed forms: a locked-wheel stop (v^2 / (2 mu_slide g)), a coast-down
// under drag and rolling resistance, the steady-state cornering radius of the linear single-track
// model, the energy balance of the brake discs, and a straight stop that stays straight.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bbw/vehicle/tyre.hpp"
#include "bbw/vehicle/vehicle.hpp"
#include "vehicle_fixture.hpp"

using namespace bbw;
using namespace bbw::vehicle;

namespace {
constexpr double kG = 9.81;
const std::array<double, 4> k20{20, 20, 20, 20};
}  // namespace

TEST(VehiclePlant, LockedWheelStopMatchesVSquaredOverTwoMuSlideG) {
  const VehicleParams p = test::load_independent();
  const double scale = 0.8;
  Vehicle v(p, test::uniform_road(scale, scale));
  const double v0 = 100.0 / 3.6;
  v.reset(v0, k20, k20);
  VehicleInputs in;
  in.clamp_force_kN = {40, 40, 40, 40};  // far above what locks the wheels
  while (!v.state().stopped && v.state().time_s < 20.0) v.step(0.001, in);
  ASSERT_TRUE(v.state().stopped);
  for (const auto& w : v.state().wheels) EXPECT_EQ(w.spin_rad_s, 0.0);
  const double mu_slide = sliding_mu(p.tyre, 3000.0, scale, scale);  // load-independent here
  EXPECT_NEAR(sliding_mu(p.tyre, 5000.0, scale, scale), mu_slide, 1e-12);
  const double expect = v0 * v0 / (2.0 * mu_slide * kG);
  EXPECT_NEAR(v.state().path_m, expect, 0.005 * expect);
  EXPECT_NEAR(v.state().y_m, 0.0, 1e-6);
}

TEST(VehiclePlant, CoastDownMatchesDragAndRollingClosedForm) {
  VehicleParams p;  // the shipped tyre; drag and rolling resistance on
  Vehicle v(p, test::uniform_road(0.85, 0.85));
  const double v0 = 30.0, v1 = 10.0;
  v.reset(v0, k20, k20);
  const VehicleInputs coast;
  while (v.state().vx_m_s > v1 && v.state().time_s < 200.0) v.step(0.001, coast);
  const ChassisParams& c = p.chassis;
  const double k = 0.5 * c.air_density_kg_m3 * c.drag_coefficient * c.frontal_area_m2;
  const double F = c.rolling_resistance * c.mass_kg * kG;
  const double m_eff = c.mass_kg + 4.0 * c.wheel_inertia_kg_m2 / (c.wheel_radius_m * c.wheel_radius_m);
  const double a = std::sqrt(F / k);
  const double t = m_eff / (k * a) * (std::atan(v0 / a) - std::atan(v1 / a));
  EXPECT_NEAR(v.state().time_s, t, 0.01 * t);
  EXPECT_FALSE(v.state().stopped);
}

TEST(VehiclePlant, SteadyStateCorneringRadiusMatchesTheLinearSingleTrackModel) {
  VehicleParams p = test::load_independent();
  Vehicle v(p, test::uniform_road(1.0, 1.0));
  const double speed = 15.0, delta = 0.015;
  v.reset(speed, k20, k20);
  VehicleInputs in;
  in.steer_rad = delta;
  while (v.state().time_s < 6.0) v.step(0.001, in);
  const ChassisParams& c = p.chassis;
  const TyreParams& t = p.tyre;
  auto ky = [&](double fz) { return t.pky1 * t.nominal_load_N * std::sin(2.0 * std::atan(fz / (t.pky2 * t.nominal_load_N))); };
  const double cf = 2.0 * ky(v.static_load_N(0)), cr = 2.0 * ky(v.static_load_N(2));
  const double L = c.wheelbase_m();
  const double K_us = c.mass_kg / L * (c.cg_to_rear_axle_m / cf - c.cg_to_front_axle_m / cr);
  const double vx = v.state().vx_m_s;
  const double curvature_expect = delta / (L + K_us * vx * vx);
  const double curvature = v.state().yaw_rate_rad_s / vx;
  EXPECT_GT(K_us, 0.0);  // the car understeers
  EXPECT_NEAR(curvature, curvature_expect, 0.03 * curvature_expect);
  EXPECT_LT(std::abs(v.state().ay_m_s2), 0.15 * kG);  // stayed in the linear range
}

TEST(VehiclePlant, DiscsTakeTheBrakingEnergy) {
  VehicleParams p = test::load_independent();
  for (BrakeParams* b : {&p.front_brake, &p.rear_brake}) {
    b->cooling_W_per_K = 0.0;
    b->cooling_W_per_K_per_m_s = 0.0;
    b->pad_mu_per_C = 0.0;
  }
  Vehicle v(p, test::uniform_road(0.85, 0.85));
  const double v0 = 25.0;
  v.reset(v0, k20, k20);
  VehicleInputs in;
  in.clamp_force_kN = {6, 6, 4, 4};  // moderate: small slip, little energy lost in the tyres
  while (!v.state().stopped) v.step(0.001, in);
  double heat_J = 0.0;
  for (std::size_t w = 0; w < 4; ++w) {
    const BrakeParams& b = p.brake(w);
    heat_J += (v.state().wheels[w].disc_C - 20.0) * b.disc_heat_capacity_J_per_K / b.heat_into_disc;
  }
  const double m_eff = p.chassis.mass_kg + 4.0 * p.chassis.wheel_inertia_kg_m2 / std::pow(p.chassis.wheel_radius_m, 2);
  const double kinetic_J = 0.5 * m_eff * v0 * v0;
  EXPECT_NEAR(heat_J, kinetic_J, 0.03 * kinetic_J);
  EXPECT_GT(v.state().wheels[0].disc_C, 40.0);
  // The caliper follows the disc slowly (time constant 120 s): it has barely started.
  EXPECT_GT(v.state().wheels[0].caliper_C, 20.0);
  EXPECT_LT(v.state().wheels[0].caliper_C, 21.0);
}

TEST(VehiclePlant, PadFrictionFollowsDiscTemperature) {
  BrakeParams b;
  EXPECT_DOUBLE_EQ(b.pad_mu(b.pad_mu_reference_C), b.pad_mu_reference);
  EXPECT_GT(b.pad_mu(200.0), b.pad_mu(100.0));
  EXPECT_LT(b.pad_mu(600.0), b.pad_mu(400.0));  // fade
}

TEST(VehiclePlant, SplitMuStopYawsTowardsTheHighSide) {
  VehicleParams p;
  RoadParams r = test::uniform_road(0.85, 0.85);
  r.surfaces.push_back({"ice", 0.085, 0.085});
  r.patches.push_back({-1e3, 1e4, 0.0, 1e3, 1});  // left half (y >= 0) icy
  Vehicle v(p, r);
  v.reset(20.0, k20, k20);
  VehicleInputs in;
  in.clamp_force_kN = {12, 12, 8, 8};
  v.step(0.001, in);
  EXPECT_LT(v.wheels()[0].surface_mu_scale, 0.1);  // left wheels on ice
  EXPECT_GT(v.wheels()[1].surface_mu_scale, 0.8);
  while (!v.state().stopped && v.state().time_s < 10.0) v.step(0.001, in);
  EXPECT_LT(v.state().yaw_rad, -0.01);  // pulled to the right (high-mu) side
}

TEST(VehiclePlant, UniformStraightStopStaysStraightAndIsDeterministic) {
  VehicleParams p;
  auto run = [&] {
    Vehicle v(p, test::uniform_road(0.85, 0.85));
    v.reset(27.0, k20, k20);
    VehicleInputs in;
    in.clamp_force_kN = {15, 15, 8, 8};
    while (!v.state().stopped && v.state().time_s < 10.0) v.step(0.001, in);
    return v.state();
  };
  const VehicleState a = run(), b = run();
  EXPECT_EQ(a.path_m, b.path_m);
  EXPECT_NEAR(a.y_m, 0.0, 1e-9);
  EXPECT_NEAR(a.yaw_rad, 0.0, 1e-12);
}

TEST(VehiclePlant, GradeSlowsAnUphillCoast) {
  VehicleParams p = test::load_independent();
  RoadParams r = test::uniform_road(0.85, 0.85);
  r.grade_percent = 10.0;
  Vehicle v(p, r);
  v.reset(20.0, k20, k20);
  const VehicleInputs coast;
  for (int i = 0; i < 1000; ++i) v.step(0.001, coast);
  const double m_eff = p.chassis.mass_kg + 4.0 * p.chassis.wheel_inertia_kg_m2 / std::pow(p.chassis.wheel_radius_m, 2);
  const double expect = 20.0 - p.chassis.mass_kg * kG * std::sin(std::atan(0.1)) / m_eff * 1.0;
  EXPECT_NEAR(v.state().vx_m_s, expect, 0.01);
}

TEST(VehiclePlant, RefusesBadParameters) {
  VehicleParams p;
  p.chassis.mass_kg = -1.0;
  EXPECT_THROW(Vehicle(p, test::uniform_road(1, 1)), std::invalid_argument);
  VehicleParams ok;
  RoadParams r = test::uniform_road(1, 1);
  r.patches.push_back({10, 5, -1, 1, 0});
  EXPECT_THROW(Vehicle(ok, r), std::invalid_argument);
  Vehicle v(ok, test::uniform_road(1, 1));
  EXPECT_THROW(v.step(0.0, {}), std::invalid_argument);
}

// Issue 15, "What is left" 3: a lower bound for the wheel lock after a dry -> ice jump at 100 km/h
// (mu_jump_dry_to_ice_100kmh), from the plant's parameters alone. The front wheel meets the ice at
// v, turning at u_j (the ABS's 0.10 slip on dry) with the clamp force F0 its dry tyre carried. On
// ice the tyre carries at most T_t = mu_peak Fz R, i.e. F_t = T_t / k with k = 2 mu_pad r_eff. The
// force stays at F0 for t_hold (detection plus the actuator's lag), then falls at r; the rim loses
//   dv = (R k / I) (F0 - F_t) (t_hold + (F0 - F_t) / (2 r))
// (the tyre taken at its peak throughout: the least loss), stops at u_min = max(0, u_j - dv) and
// spins up at no more than a_s = R (T_t - f_r Fz R) / I while half the car's speed falls at a_car / 2.
// The lock (below half the car's speed) lasts at least (v/2 - u_min) / (a_s + a_car/2): the time
// before u_min is left out. Inputs measured in the run's vehicle.csv: v, the disc at 49 C, the
// e-caliper's release after the command (15.3 -> 0.9 kN: 13 ms lag, then 118 kN/s on average -
// the corner's 25 rev/s speed limit on the clamp curve's slope, 150 kN/s at 12 kN, 95 at 3 kN).
TEST(VehiclePlant, AJumpToIceLocksTheWheelLongerThan100msWithThisCaliper) {
  const VehicleParams p;  // config/vehicle/sedan.yaml
  const auto& c = p.chassis;
  const double dry = 0.8518, ice = 0.0852;  // sedan.yaml's surfaces
  const double v = 23.99;                   // car speed at the jump (vehicle.csv, t = 0.706 s)
  const double R = c.wheel_radius_m, I = c.wheel_inertia_kg_m2, L = c.wheelbase_m(), h = c.cg_height_m;
  const auto front_wheel_load = [&](double decel) {
    return 0.5 * c.mass_kg * (kG * c.cg_to_rear_axle_m + decel * h) / L;
  };
  const double k = 2.0 * p.front_brake.pad_mu(49.0) * p.front_brake.effective_radius_m;
  const double fz_dry = front_wheel_load(9.45);  // the dry stop's deceleration before the jump
  const double F0 = longitudinal_mu(p.tyre, fz_dry, 0.10, dry, dry) * fz_dry * R / k;
  const double u_j = (1.0 - 0.10) * v;
  const double mu_peak = peak_longitudinal_mu(p.tyre, front_wheel_load(1.0), ice, ice).mu;
  const double a_car = mu_peak * kG + 0.5 * c.air_density_kg_m3 * c.drag_coefficient * c.frontal_area_m2 * v * v / c.mass_kg;
  const double fz_ice = front_wheel_load(a_car);
  const double Tt = peak_longitudinal_mu(p.tyre, fz_ice, ice, ice).mu * fz_ice * R;
  const double Ft = Tt / k;
  const double a_s = R * (Tt - c.rolling_resistance * fz_ice * R) / I;
  const double closing = a_s + 0.5 * a_car;
  const auto lock_bound = [&](double t_hold, double rate_N_s) {
    const double dv = R * k / I * (F0 - Ft) * (t_hold + (F0 - Ft) / (2.0 * rate_N_s));
    return std::max(0.0, 0.5 * v - std::max(0.0, u_j - dv)) / closing;
  };
  // The rate a release needs so that the bound allows 100 ms: dv <= u_j - v/2 + 0.1 s closing.
  const auto rate_needed = [&](double t_hold) {
    const double room = (u_j - 0.5 * v + 0.1 * closing) / (R * k / I) - (F0 - Ft) * t_hold;
    return (F0 - Ft) * (F0 - Ft) / (2.0 * room);
  };
  const double rate = 118e3;
  std::printf("F0 %.2f kN (k %.4f m), ice: Fz %.0f N, mu_peak %.4f, F_t %.2f kN; wheel decel %.0f m/s^2, "
              "spin-up <= %.1f m/s^2\n", F0 / 1e3, k, fz_ice, Tt / (fz_ice * R), Ft / 1e3,
              R * (k * F0 - Tt) / I, a_s);
  std::printf("lock >= %.3f s (hold 26 ms, as run), %.3f s (13 ms: the lag alone), %.3f s (no hold)\n",
              lock_bound(0.026, rate), lock_bound(0.013, rate), lock_bound(0.0, rate));
  std::printf("rate for 100 ms: %.0f / %.0f / %.0f kN/s (hold 26 / 13 / 0 ms)\n", rate_needed(0.026) / 1e3,
              rate_needed(0.013) / 1e3, rate_needed(0.0) / 1e3);
  EXPECT_NEAR(F0, 15.3e3, 0.5e3);  // the run's clamp force at the jump
  EXPECT_GT(lock_bound(0.0, rate), 0.1);  // even an instant release at this rate locks too long
  EXPECT_GT(rate_needed(0.013), 1.5 * rate);
}
