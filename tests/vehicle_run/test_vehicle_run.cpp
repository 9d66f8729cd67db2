// The vehicle run in one process: every shipped vehicle scenario loads; a dry stop is
// deterministic, runs the vehicle and pedal as participants of the CCU's barrier, stops, keeps
// its wheels from locking and stays in lane; bad scenarios are refused with file, line and key.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/vehicle/tyre.hpp"
#include "bbw/vehicle_run/metrics.hpp"
#include "bbw/vehicle_run/vehicle_run.hpp"

using namespace bbw;

namespace {
std::string src() {
  const char* env = std::getenv("BBW_SOURCE_DIR");
  return env ? env : BBW_SOURCE_DIR_FALLBACK;
}
std::string scen(const std::string& name) { return src() + "/config/scenarios/vehicle/" + name + ".yaml"; }
calibration::CalibratorConfig calibrator() { return calibration::load_config(src() + "/config/calibrator/robust.yaml"); }
}  // namespace

TEST(VehicleScenario, EveryShippedScenarioLoads) {
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(src() + "/config/scenarios/vehicle")) {
    if (e.path().extension() != ".yaml") continue;
    EXPECT_NO_THROW(vehicle_run::load_vehicle_scenario(e.path().string())) << e.path();
    EXPECT_TRUE(vehicle_run::is_vehicle_scenario(e.path().string()));
    ++n;
  }
  EXPECT_GE(n, 12);
  EXPECT_FALSE(vehicle_run::is_vehicle_scenario(src() + "/config/scenarios/vehicle_stop.yaml"));
}

TEST(VehicleScenario, UnknownSurfaceNamesFileLineAndKey) {
  std::ifstream in(scen("dry_straight_100kmh"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("surface: dry"), 12, "surface: lava");
  const std::string file = (std::filesystem::temp_directory_path() / "bbw_vehicle_bad.yaml").string();
  std::filesystem::copy_file(scen("dry_straight_100kmh"), file, std::filesystem::copy_options::overwrite_existing);
  std::ofstream(file) << text;
  // Relative paths resolve beside the file: point them back into the tree.
  std::string fixed = text;
  for (const std::string key : {"corners: ", "vehicle: ", "brake_control: "}) {
    const auto p = fixed.find("\n" + key) + 1;
    fixed.insert(p + key.size(), src() + "/config/scenarios/vehicle/");
  }
  std::ofstream(file) << fixed;
  try {
    vehicle_run::load_vehicle_scenario(file);
    FAIL() << "accepted an unknown surface";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.key_path(), "road.surface");
    EXPECT_GT(e.line(), 0);
    EXPECT_NE(std::string(e.what()).find("lava"), std::string::npos);
  }
  std::filesystem::remove(file);
}

TEST(VehicleScenario, TheProcessListIsCheckedWithItsLine) {
  std::ifstream in(scen("dry_straight_100kmh"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const std::string key : {"corners: ", "vehicle: ", "brake_control: "}) {
    const auto p = text.find("\n" + key) + 1;
    text.insert(p + key.size(), src() + "/config/scenarios/vehicle/");
  }
  const std::string file = (std::filesystem::temp_directory_path() / "bbw_vehicle_processes.yaml").string();
  auto expect_error = [&](const std::string& body, const std::string& what) {
    std::ofstream(file) << body;
    try {
      vehicle_run::load_vehicle_scenario(file);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const config::ConfigError& e) {
      EXPECT_EQ(e.key_path(), "processes") << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  std::string t = text;
  t.replace(t.find("processes: [ccu, FL, FR, RL, RR, vehicle, pedal]"), 48, "processes: [ccu, FL, FR, RL, RR, vehicle, pedal, radar]");
  expect_error(t, "unknown process 'radar'");
  t = text;
  t.replace(t.find("processes: [ccu, FL, FR, RL, RR, vehicle, pedal]"), 48, "processes: [ccu, FL, FR, RL, RR, vehicle]");
  expect_error(t, "runs pedal too");
  t = text;
  t.replace(t.find("processes: [ccu, FL, FR, RL, RR, vehicle, pedal]"), 48, "processes: ccu");
  expect_error(t, "list of strings");
  std::filesystem::remove(file);
}

TEST(VehicleRun, DryStopIsDeterministicLockstepAndStops) {
  const auto s = vehicle_run::load_vehicle_scenario(scen("dry_straight_100kmh"));
  const auto cal = calibrator();
  vehicle_run::VehicleRunOptions o;
  vehicle_run::VehicleRun a(s, cal, o), b(s, cal, o);
  a.run();
  b.run();
  ASSERT_EQ(a.trace().size(), b.trace().size());
  for (std::size_t i = 0; i < a.trace().size(); ++i) {
    ASSERT_EQ(a.trace()[i].path_m, b.trace()[i].path_m) << i;
    ASSERT_EQ(a.trace()[i].command_kN, b.trace()[i].command_kN) << i;
  }
  const auto m = vehicle_run::vehicle_metrics(s, a);
  EXPECT_TRUE(m.stopped);
  // Physically possible and not absurd (the measured figure is in docs/vehicle.md).
  EXPECT_GT(m.distance_ratio, 1.0);
  EXPECT_LT(m.distance_ratio, 1.3);
  for (double l : m.longest_wheel_lock_s) EXPECT_LT(l, 0.1);
  EXPECT_LT(m.max_lateral_deviation_m, 0.5);
  // The CCU commanded the corners (not the corner scenario's zero demand).
  double max_cmd = 0.0;
  for (const auto& t : a.trace()) max_cmd = std::max(max_cmd, t.command_kN[0]);
  EXPECT_GT(max_cmd, 5.0);
}

TEST(VehicleRun, WithoutABSTheWheelsLock) {
  auto s = vehicle_run::load_vehicle_scenario(scen("dry_straight_100kmh"));
  s.brake.abs_enabled = false;
  vehicle_run::VehicleRun r(s, calibrator(), {});
  r.run();
  const auto m = vehicle_run::vehicle_metrics(s, r);
  double longest = 0.0;
  for (double l : m.longest_wheel_lock_s) longest = std::max(longest, l);
  EXPECT_GT(longest, 0.5);
}

// A laden car (300 kg in the boot: 1393 kg, the centre of gravity 0.3 m further back) brakes
// with the CCU's nominal 1093 kg model: the driver's full pedal, turned into force with the
// nominal mass, asks too little. The CCU estimates the mass from the car's own braking
// (docs/vehicle.md, "A population of cars") and stops it shorter than without the estimate; the
// nominal car's estimate stays within the deadband (its stops unchanged: the scenario tables).
TEST(VehicleRun, ALadenCarsMassIsEstimatedFromItsOwnBraking) {
  auto s = vehicle_run::load_vehicle_scenario(scen("dry_straight_100kmh"));
  const double nominal_kg = s.brake.car.mass_kg;
  vehicle_run::VehicleRun nominal(s, calibrator(), {});
  nominal.run();
  EXPECT_EQ(nominal.brake().mass_used_kg(), nominal_kg);
  auto& c = s.vehicle.vehicle.chassis;
  const double L = c.cg_to_front_axle_m + c.cg_to_rear_axle_m;
  const double m0 = c.mass_kg, payload = 300.0, x_payload = 2.4;
  const double a = (m0 * c.cg_to_front_axle_m + payload * x_payload) / (m0 + payload);
  c.yaw_inertia_kg_m2 += m0 * (a - c.cg_to_front_axle_m) * (a - c.cg_to_front_axle_m) + payload * (x_payload - a) * (x_payload - a);
  c.mass_kg = m0 + payload;
  c.cg_to_front_axle_m = a;
  c.cg_to_rear_axle_m = L - a;
  vehicle_run::VehicleRun laden(s, calibrator(), {});
  laden.run();
  const auto m = vehicle_run::vehicle_metrics(s, laden);
  EXPECT_GT(laden.brake().mass_estimate_kg(), 0.95 * c.mass_kg);  // within its bias (about +10 %) of the truth
  EXPECT_LT(laden.brake().mass_estimate_kg(), 1.25 * c.mass_kg);
  EXPECT_GT(laden.brake().mass_used_kg(), nominal_kg + 150.0);
  s.brake.mass.enabled = false;
  vehicle_run::VehicleRun off(s, calibrator(), {});
  off.run();
  EXPECT_EQ(off.brake().mass_used_kg(), nominal_kg);
  const auto m_off = vehicle_run::vehicle_metrics(s, off);
  std::printf("laden: mass %.0f kg, estimate %.0f kg, used %.0f kg; stop %.2f m (without the estimate %.2f m)\n", c.mass_kg,
              laden.brake().mass_estimate_kg(), laden.brake().mass_used_kg(), m.stopping_distance_m, m_off.stopping_distance_m);
  EXPECT_LT(m.stopping_distance_m, m_off.stopping_distance_m - 1.5);
  for (double l : m.longest_wheel_lock_s) EXPECT_LT(l, 0.1);
}

TEST(VehicleRun, ALostCornersBrakingGoesToTheOtherThree) {
  // FL lost 0.5 s into an ABS stop (docs/vehicle.md): 67.2 m before the redistribution, 60.5 m
  // measured with it (healthy 42.3 m). Regression bound on the measured figure; without the
  // redistribution the same run must be longer.
  auto s = vehicle_run::load_vehicle_scenario(scen("dry_fault_FL_lost_abs"));
  vehicle_run::VehicleRunOptions o;
  o.in_process.process_faults = true;  // the corner kill, as bbw_vehicle_inproc does
  vehicle_run::VehicleRun r(s, calibrator(), o);
  r.run();
  const auto m = vehicle_run::vehicle_metrics(s, r);
  EXPECT_TRUE(m.stopped);
  EXPECT_LT(m.stopping_distance_m, 62.0);
  EXPECT_LT(m.max_lateral_deviation_m, 2.0);
  for (double l : m.longest_wheel_lock_s) EXPECT_LT(l, 0.1);
  s.brake.yaw.redistribute_lost_corner = false;
  vehicle_run::VehicleRun off(s, calibrator(), o);
  off.run();
  EXPECT_GT(vehicle_run::vehicle_metrics(s, off).stopping_distance_m, m.stopping_distance_m + 3.0);
}

TEST(VehicleRun, IceMeetsTheDistanceGoalAndSplitMuStaysWithinItsMeasuredBounds) {
  // docs/vehicle.md, issue 15 fourth part (measured once): ice ratio 0.964 (goal <= 1.10, met),
  // epsilon 0.933 (regression bound 0.85; goal 0.95 not met); split-mu 121.66 m, lateral 0.75 m
  // (goal 0.5 m not met: regression bounds; the yaw-moment limitation trades distance for lane
  // keeping, 94.26 m / 1.30 m before the third part).
  auto ice = vehicle_run::load_vehicle_scenario(scen("ice_straight_100kmh"));
  vehicle_run::VehicleRun a(ice, calibrator(), {});
  a.run();
  const auto mi = vehicle_run::vehicle_metrics(ice, a);
  EXPECT_TRUE(mi.stopped);
  EXPECT_LE(mi.distance_ratio, 1.10);
  EXPECT_GE(mi.adhesion_utilisation, 0.85);
  auto split = vehicle_run::load_vehicle_scenario(scen("split_mu_dry_ice_100kmh"));
  vehicle_run::VehicleRun b(split, calibrator(), {});
  b.run();
  const auto ms = vehicle_run::vehicle_metrics(split, b);
  EXPECT_TRUE(ms.stopped);
  EXPECT_LT(ms.stopping_distance_m, 125.0);
  EXPECT_LT(ms.max_lateral_deviation_m, 1.0);
}

TEST(VehicleRun, TheSplitMuDetectionStaysQuietInACurveAndOnUniformSnow) {
  // Issue 15 third part: braking in a curve loads the outer wheels, so the inner front wheel's ABS
  // torque falls below 0.6 of the outer's - no split-mu (the detection compares torque per
  // estimated wheel load and the tyres' estimated mu); on uniform snow the slip controllers'
  // torques swing apart for a moment - no split-mu either (it fired at 0.97 s and 0.30 s before).
  for (const char* name : {"tuning/t_curve_dry_b_right_80m_65kmh", "tuning/t_snow_b_120"}) {
    const auto s = vehicle_run::load_vehicle_scenario(scen(name));
    vehicle_run::VehicleRun r(s, calibrator(), {});
    r.run();
    for (const auto& t : r.trace()) ASSERT_FALSE(t.split_mu) << name << " at " << t.time_s << " s";
  }
  const auto split = vehicle_run::load_vehicle_scenario(scen("split_mu_dry_ice_100kmh"));
  vehicle_run::VehicleRun b(split, calibrator(), {});
  b.run();
  bool seen = false;
  for (const auto& t : b.trace()) seen = seen || (t.split_mu && t.time_s < 0.5);
  EXPECT_TRUE(seen);
}

TEST(VehicleRun, TheCaliperTemperatureComesFromTheDriving) {
  auto s = vehicle_run::load_vehicle_scenario(scen("dry_straight_100kmh"));
  s.disc_C = {400.0, 40.0, 40.0, 40.0};  // FL's disc hot: its caliper warms during the run
  vehicle_run::VehicleRun r(s, calibrator(), {});
  auto fl = r.in_process().block_topic(0).receiver();
  r.run();
  msg::MeasurementBlock b, last;
  while (fl->take(b)) {
    if (!b.samples().empty()) last = b;
  }
  ASSERT_FALSE(last.samples().empty());
  const double sensed = last.samples().back().temperature_C();
  const double vehicle_C = r.vehicle().state().wheels[0].caliper_C;
  EXPECT_GT(vehicle_C, s.caliper_C[0] + 2.0);
  EXPECT_NEAR(sensed, vehicle_C, 0.5);  // the plant's temperature sensor reads the vehicle's caliper
}

// The corners take the vehicle's caliper temperatures every N periods only (one small message per
// N periods over DDS instead of the vehicle's sensors every period: docs/vehicle.md, "Speed"):
// period k's plant uses the temperature of the newest sent step below k, as bbw_corner waits for.
TEST(VehicleRun, TheCornersTakeTheCaliperTemperatureEveryNPeriods) {
  constexpr std::uint64_t kN = msg::CALIPER_TEMPERATURE_EVERY_PERIODS;
  static_assert(kN > 1);
  EXPECT_EQ(node::caliper_temperature_step(0), -1);
  EXPECT_EQ(node::caliper_temperature_step(kN - 1), -1);
  EXPECT_EQ(node::caliper_temperature_step(kN), static_cast<std::int64_t>(kN) - 1);
  EXPECT_EQ(node::caliper_temperature_step(2 * kN - 1), static_cast<std::int64_t>(kN) - 1);
  EXPECT_TRUE(node::caliper_temperature_sent_after(kN - 1));
  EXPECT_FALSE(node::caliper_temperature_sent_after(kN));

  auto s = vehicle_run::load_vehicle_scenario(scen("dry_straight_100kmh"));
  s.disc_C = {400.0, 40.0, 40.0, 40.0};  // FL's caliper warms all the time
  vehicle_run::VehicleRun r(s, calibrator(), {});
  std::vector<double> vehicle_C;  // the vehicle's FL caliper at the end of each period
  std::size_t changes = 0;
  double applied_before = r.in_process().corner(0).caliper_temperature_C();
  EXPECT_TRUE(std::isnan(applied_before));  // the scenario's own temperature until the first send
  while (r.step()) {
    const std::uint64_t k = r.in_process().periods_done() - 1;  // the period just simulated
    vehicle_C.push_back(r.vehicle().state().wheels[0].caliper_C);
    const double applied = r.in_process().corner(0).caliper_temperature_C();  // for period k + 1
    const std::int64_t step = node::caliper_temperature_step(k + 1);
    if (step < 0) {
      EXPECT_TRUE(std::isnan(applied)) << "period " << k;
    } else {
      ASSERT_EQ(applied, vehicle_C[static_cast<std::size_t>(step)]) << "period " << k;
    }
    if (!(applied == applied_before) && !(std::isnan(applied) && std::isnan(applied_before))) ++changes;
    applied_before = applied;
    if (k > 40 * kN) break;
  }
  EXPECT_EQ(vehicle_C.size(), 40 * kN + 2);
  EXPECT_GT(vehicle_C.back(), vehicle_C.front());  // the caliper did warm: each send was a change
  EXPECT_EQ(changes, 40u);  // after periods N - 1, 2N - 1, ..., 40N - 1
}

// The per-axle adhesion's sweep is cut short where no time that counts can come (locked runs end
// at the lock; runs slower than 1.05 x the shortest so far end early): the same figures, to the
// last bit, as the whole sweep of every 0.25 kN step to 30 s each (computed at commit 4e74a6a,
// which took 2.0 / 11.0 s for dry / ice against 0.28 / 0.29 s now).
TEST(Regulation, AxleAdhesionCutShortEqualsTheWholeSweep) {
  struct Pinned {
    const char* scenario;
    double front, rear, z_front, z_rear;
  };
  for (const Pinned& e : {Pinned{"dry_straight_100kmh", 0.97901964304843458, 1.0397395439248331, 0.69947973867501911,
                                 0.38291133468223021},
                          Pinned{"ice_straight_100kmh", 0.096466394572603587, 0.11015287812218404,
                                 0.061259887106924892, 0.053585768217113611}}) {
    const auto s = vehicle_run::load_vehicle_scenario(scen(e.scenario));
    const vehicle_run::AxleAdhesion k = vehicle_run::axle_adhesion(s.vehicle.vehicle, s.road);
    EXPECT_EQ(k.front, e.front) << e.scenario;
    EXPECT_EQ(k.rear, e.rear) << e.scenario;
    EXPECT_EQ(k.z_front, e.z_front) << e.scenario;
    EXPECT_EQ(k.z_rear, e.z_rear) << e.scenario;
  }
}

// UN R13-H Annex 6 Appendix 2's per-axle adhesion from simulated runs without anti-lock: a
// constant clamp force cannot hold the tyre at its peak all the way from 40 to 20 km/h, so each
// axle's coefficient is below the tyre model's peak at the axle's load, but not far below it.
TEST(Regulation, AxleAdhesionFromRunsWithoutAntiLockIsJustBelowTheTyresPeak) {
  const auto s = vehicle_run::load_vehicle_scenario(scen("dry_straight_100kmh"));
  const vehicle::VehicleParams& p = s.vehicle.vehicle;
  const vehicle_run::AxleAdhesion k = vehicle_run::axle_adhesion(p, s.road);
  const vehicle::Surface& road = s.road.surface_at(0.0, 0.0);
  const vehicle::ChassisParams& c = p.chassis;
  const double W = c.mass_kg * 9.81, E = c.wheelbase_m();
  // The braked axle's dynamic load at the rate measured, and the tyre's peak at half of it.
  const double front_N = W * c.cg_to_rear_axle_m / E + c.cg_height_m / E * k.z_front * W;
  const double rear_N = W * c.cg_to_front_axle_m / E - c.cg_height_m / E * k.z_rear * W;
  const double mu_f = vehicle::peak_longitudinal_mu(p.tyre, 0.5 * front_N, road.mu_scale, road.stiffness_scale).mu;
  const double mu_r = vehicle::peak_longitudinal_mu(p.tyre, 0.5 * rear_N, road.mu_scale, road.stiffness_scale).mu;
  EXPECT_LT(k.front, mu_f);
  EXPECT_GT(k.front, 0.85 * mu_f);
  EXPECT_LT(k.rear, mu_r);
  EXPECT_GT(k.rear, 0.85 * mu_r);
}
