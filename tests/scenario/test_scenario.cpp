#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <tuple>

#include <Eigen/Dense>

#include "bbw/plant/clamp_curve.hpp"
#include "bbw/plant/params_yaml.hpp"
#include "bbw/scenario/corner_sim.hpp"
#include "bbw/scenario/load.hpp"

using namespace bbw;
namespace fs = std::filesystem;

namespace {

std::string source_dir() {
  const char* s = std::getenv("BBW_SOURCE_DIR");
  return s ? s : BBW_TEST_SOURCE_DIR;
}

// A scenario text next to the real plant file (so `plant:` resolves), named as if it were
// config/scenarios/test.yaml.
std::string scenario_name() { return source_dir() + "/config/scenarios/test.yaml"; }

const char* kGood = R"(name: t
seed: 3
duration_s: 2.0
plant: ../plant/ecaliper.yaml
corners:
  - name: A
    temperature_C: 30.0
    drive:
      mode: position
      segments:
        - type: sine
          offset_rev: 3.0
          amplitude_rev: 1.0
          period_s: 1.0
)";

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto pos = s.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) s.replace(pos, from.size(), to);
  return s;
}

// Loads `text`; expects a ConfigError whose message holds every fragment.
void expect_error(const std::string& text, const std::vector<std::string>& fragments) {
  try {
    scenario::load_scenario_string(text, scenario_name());
    ADD_FAILURE() << "no error for:\n" << text;
  } catch (const config::ConfigError& e) {
    const std::string msg = e.what();
    for (const auto& f : fragments) EXPECT_NE(msg.find(f), std::string::npos) << "'" << f << "' not in: " << msg;
  }
}

}  // namespace

TEST(ScenarioLoader, LoadsAGoodFileWithDefaults) {
  const auto s = scenario::load_scenario_string(kGood, scenario_name());
  EXPECT_EQ(s.name, "t");
  EXPECT_EQ(s.seed, 3u);
  EXPECT_DOUBLE_EQ(s.plant_dt_s, 0.001);
  EXPECT_DOUBLE_EQ(s.ccu_period_s, 0.005);
  ASSERT_EQ(s.corners.size(), 1u);
  EXPECT_FALSE(s.corners[0].effects.backlash.enabled);
  EXPECT_DOUBLE_EQ(s.corners[0].sensors.load_cell_noise_kN, 0.03);
  EXPECT_FALSE(s.corners[0].axle.has_value());
}

TEST(ScenarioLoader, UnknownKey) {
  expect_error(replace(kGood, "seed: 3", "seed: 3\nsed: 4"), {"test.yaml:3", "key 'sed'", "unknown key"});
  expect_error(replace(kGood, "period_s: 1.0", "period_s: 1.0\n          phase: 2"),
               {"key 'corners[0].drive.segments[0].phase'", "unknown key"});
}

TEST(ScenarioLoader, MissingKey) {
  expect_error(replace(kGood, "duration_s: 2.0\n", ""), {"test.yaml", "key 'duration_s'", "required key is missing"});
  expect_error(replace(kGood, "    temperature_C: 30.0\n", ""), {"key 'corners[0].temperature_C'", "required"});
}

TEST(ScenarioLoader, WrongType) {
  expect_error(replace(kGood, "duration_s: 2.0", "duration_s: long"), {"test.yaml:3", "duration_s", "must be a number"});
  expect_error(replace(kGood, "mode: position", "mode: [position]"), {"corners[0].drive.mode", "must be a string"});
}

TEST(ScenarioLoader, OutOfRange) {
  expect_error(replace(kGood, "temperature_C: 30.0", "temperature_C: 300.0"),
               {"test.yaml:7", "corners[0].temperature_C", "must be in [-40, 140]", "300"});
  expect_error(replace(kGood, "duration_s: 2.0", "duration_s: 2.0\nplant_dt_s: 0.02\nccu_period_s: 0.01"),
               {"plant_dt_s", "must be in"});
  expect_error(replace(kGood, "type: sine", "type: spiral"), {"segments[0].type", "must be one of", "spiral"});
}

TEST(ScenarioLoader, EffectsAndSensorOverrides) {
  const std::string text = replace(kGood, "    drive:", R"(    effects:
      backlash: {width_rev: 0.03}
      creep: {enabled: false}
      sensor_delay: {delay_s: 0.004}
    sensor:
      load_cell_noise_kN: 0.05
    wear: {initial_rev: 0.1, rate_rev_per_kN_s: 1.0e-6}
    drive:)");
  const auto s = scenario::load_scenario_string(text, scenario_name());
  const auto& c = s.corners[0];
  EXPECT_TRUE(c.effects.backlash.enabled);
  EXPECT_DOUBLE_EQ(c.effects.backlash.width_rev, 0.03);
  EXPECT_FALSE(c.effects.creep.enabled);
  EXPECT_TRUE(c.effects.sensor_delay.enabled);
  EXPECT_FALSE(c.effects.viscous_friction.enabled);
  EXPECT_DOUBLE_EQ(c.sensors.load_cell_noise_kN, 0.05);
  EXPECT_DOUBLE_EQ(c.sensors.external_noise_kN, 0.005);
  EXPECT_DOUBLE_EQ(c.conditions.wear_initial_rev, 0.1);
  expect_error(replace(text, "width_rev: 0.03", "width: 0.03"), {"effects.backlash.width", "unknown key"});
  expect_error(replace(text, "delay_s: 0.004", "delay_s: 3"), {"effects.sensor_delay.delay_s", "must be in [0, 1]"});
}

TEST(ScenarioLoader, ForceBreakpointsAndDemand) {
  const std::string force = replace(kGood, R"(      mode: position
      segments:
        - type: sine
          offset_rev: 3.0
          amplitude_rev: 1.0
          period_s: 1.0
)", "      mode: force\n      feedback: compensated\n      breakpoints: [[0, 0], [1, 20], [2, 5]]\n");
  const auto s = scenario::load_scenario_string(force, scenario_name());
  EXPECT_EQ(s.corners[0].drive.mode, scenario::DriveMode::Force);
  EXPECT_EQ(s.corners[0].drive.feedback, corner_unit::ForceFeedback::Compensated);
  ASSERT_EQ(s.corners[0].drive.force_kN.size(), 3u);
  EXPECT_DOUBLE_EQ(s.corners[0].drive.force_kN[1].value, 20.0);
  expect_error(replace(force, "[1, 20], [2, 5]", "[2, 20], [1, 5]"), {"breakpoints[2]", "times must increase strictly"});
  expect_error(replace(force, "[1, 20]", "[1, 20, 3]"), {"breakpoints[1]", "must be a pair"});
  expect_error(replace(force, "breakpoints:", "feedback_gain: 2\n      breakpoints:"), {"drive.feedback_gain", "unknown key"});
  expect_error(replace(force, "mode: force", "mode: demand"), {"drive.breakpoints", "unknown key"});
  const std::string demand = replace(replace(force, "      breakpoints: [[0, 0], [1, 20], [2, 5]]\n", ""), "mode: force",
                                     "mode: demand");
  expect_error(demand, {"corners[0].drive", "needs a top-level 'demand:'"});
  const std::string with_demand =
      replace(demand, "corners:", "demand:\n  max_clamp_force_kN: 30\n  front_share: 0.6\n  profile: [[0, 0], [1, 1]]\ncorners:");
  expect_error(with_demand, {"corners[0].axle", "needs 'axle: front|rear'"});
  const auto d = scenario::load_scenario_string(replace(with_demand, "name: A", "name: A\n    axle: rear"), scenario_name());
  ASSERT_TRUE(d.demand.has_value());
  EXPECT_NEAR(d.demand->axle_factor(scenario::Axle::Rear), 0.4 / 0.6, 1e-12);
  expect_error(replace(with_demand, "front_share: 0.6", "front_share: 0.3"), {"demand.front_share", "must be in [0.5, 0.9]"});
}

TEST(ScenarioLoader, DuplicateCornerAndBadPlantFile) {
  const std::string two = std::string(kGood) + R"(  - name: A
    temperature_C: 31.0
    drive: {mode: position, segments: [{type: hold, position_rev: 2, duration_s: 1}]}
)";
  expect_error(two, {"corners[1].name", "duplicate corner name 'A'"});
  expect_error(replace(kGood, "../plant/ecaliper.yaml", "../plant/nope.yaml"), {"nope.yaml", "cannot open file"});
}

TEST(ScenarioLoader, ExtraKeysHookReadsForeignTopLevelKeys) {
  const std::string text = std::string(kGood) + "faults:\n  - {corner: A, at_s: 1.0}\n";
  expect_error(text, {"key 'faults'", "unknown key"});
  std::size_t seen = 0;
  const auto s = scenario::load_scenario_string(text, scenario_name(), [&](config::Reader& top) {
    seen = top.maps("faults").size();
  });
  EXPECT_EQ(seen, 1u);
  EXPECT_EQ(s.corners.size(), 1u);
}

// Every YAML file under config/plant/ and config/scenarios/ must load. config/scenarios/faults/
// belongs to the fault-injection work, whose own loader (through the ExtraKeys hook) and tests
// cover it, so it is skipped here.
TEST(ConfigFiles, EveryPlantAndScenarioFileLoads) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(source_dir() + "/config/plant")) {
    if (e.path().extension() != ".yaml") continue;
    EXPECT_NO_THROW(plant::load_plant_params(e.path().string())) << e.path();
    ++n;
  }
  const fs::path scenarios = source_dir() + "/config/scenarios";
  for (auto it = fs::recursive_directory_iterator(scenarios); it != fs::recursive_directory_iterator(); ++it) {
    // Fault and vehicle scenarios have their own loaders (tests/faults, tests/vehicle_run).
    if (it->is_directory() && (it->path().filename() == "faults" || it->path().filename() == "vehicle")) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->path().extension() != ".yaml") continue;
    try {
      const auto s = scenario::load_scenario(it->path().string());
      for (std::size_t c = 0; c < s.corners.size(); ++c) scenario::CornerSim sim(s, c);
    } catch (const std::exception& ex) {
      ADD_FAILURE() << it->path() << ": " << ex.what();
    }
    ++n;
  }
  EXPECT_GE(n, 5);
}

TEST(ConfigFiles, DefaultPlantFileEqualsTheCodeDefaults) {
  const auto p = plant::load_plant_params(source_dir() + "/config/plant/ecaliper.yaml");
  const plant::PlantParams d;
  EXPECT_EQ(p.key_friction.half_width_kN, d.key_friction.half_width_kN);
  EXPECT_EQ(p.key_friction.structure_seed, d.key_friction.structure_seed);
  EXPECT_EQ(p.curve.exp_coefficient_kN, d.curve.exp_coefficient_kN);
  EXPECT_EQ(p.curve.contact_shift_rev_per_C, d.curve.contact_shift_rev_per_C);
  EXPECT_EQ(p.sensors.load_cell_noise_kN, d.sensors.load_cell_noise_kN);
  EXPECT_EQ(p.motor.torque_constant_Nm_per_A, d.motor.torque_constant_Nm_per_A);
  EXPECT_EQ(p.transmission.lead_mm_per_rev, d.transmission.lead_mm_per_rev);
}

TEST(PlantConfig, BrokenPlantFileNamesTheKey) {
  const auto dir = fs::temp_directory_path() / "bbw_test_plant_cfg";
  fs::create_directories(dir);
  std::ifstream in(source_dir() + "/config/plant/ecaliper.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string file = (dir / "bad.yaml").string();
  std::ofstream(file) << replace(text, "gear_ratio: 12.0", "gear_ratio: -12.0");
  try {
    plant::load_plant_params(file);
    ADD_FAILURE() << "no error";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("transmission.gear_ratio"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("must be > 0"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(Profiles, PaperSweepIsContinuousValleyToValleyWithConsistentRates) {
  scenario::PositionProfileSpec spec;
  spec.segments.push_back(scenario::PaperSweep{1.0, {0.5, 1.0, 5.0}, 2.0, 2});
  spec.segments.push_back(scenario::LocalLoops{{2.5, 4.0}, 0.3, 1.0, 2, 1.0});
  const scenario::PositionProfile p(spec);
  EXPECT_NEAR(p.duration_s(), 1.0 + 3 * 2 * 2.0 + 2 * (1.0 + 2.0), 1e-12);
  EXPECT_NEAR(p.max_rev(), 6.0, 1e-12);
  EXPECT_NEAR(p.at(1.0).value, 1.0, 1e-12);
  EXPECT_NEAR(p.at(5.0).value, 1.0, 1e-12);  // after the two 0.5 rev cycles
  const double h = 1e-5;
  for (double t = 0.0; t < p.duration_s() + 1.0; t += 0.0137) {
    const auto r = p.at(t);
    EXPECT_NEAR(p.at(t + h).value, r.value, 0.01) << t;  // continuous
    EXPECT_NEAR((p.at(t + h).value - p.at(t - h).value) / (2 * h), r.rate, 1e-3) << t;
  }
}

TEST(Profiles, BreakpointsInterpolateLinearly) {
  const scenario::BreakpointProfile b({{0.0, 0.0}, {1.0, 10.0}, {3.0, 0.0}});
  EXPECT_DOUBLE_EQ(b.at(-1.0).value, 0.0);
  EXPECT_DOUBLE_EQ(b.at(0.5).value, 5.0);
  EXPECT_DOUBLE_EQ(b.at(2.0).value, 5.0);
  EXPECT_DOUBLE_EQ(b.at(2.0).rate, -5.0);
  EXPECT_DOUBLE_EQ(b.at(9.0).value, 0.0);
  EXPECT_THROW(scenario::BreakpointProfile({{1.0, 0.0}, {1.0, 2.0}}), std::invalid_argument);
}

TEST(CornerSim, SameScenarioAndCornerGiveIdenticalSamples) {
  const auto s = scenario::load_scenario(source_dir() + "/config/scenarios/four_corner_rig.yaml");
  scenario::CornerSim a(s, 1), b(s, 1), c(s, 2);
  bool differs = false;
  for (int i = 0; i < 3000; ++i) {
    const auto& x = a.step(s.plant_dt_s);
    const auto& y = b.step(s.plant_dt_s);
    const auto& z = c.step(s.plant_dt_s);
    ASSERT_EQ(x.force_internal_kN, y.force_internal_kN);
    ASSERT_EQ(x.position_rev, y.position_rev);
    ASSERT_EQ(x.seq, static_cast<std::uint64_t>(i + 1));
    differs = differs || x.force_internal_kN != z.force_internal_kN;
  }
  EXPECT_TRUE(differs);
  EXPECT_THROW(scenario::CornerSim(s, 4), std::out_of_range);
}

TEST(CornerSim, ExternalForceCommandTakesOver) {
  const auto s = scenario::load_scenario(source_dir() + "/config/scenarios/four_corner_rig.yaml");
  scenario::CornerSim sim(s, 0);
  scenario::ExternalInputs ext;
  ext.force_command_kN = 15.0;
  for (int i = 0; i < 2000; ++i) sim.step(s.plant_dt_s, ext);
  EXPECT_EQ(sim.last().command_kind, scenario::CommandKind::Force);
  EXPECT_DOUBLE_EQ(sim.last().command, 15.0);
  EXPECT_NEAR(sim.last().force_internal_kN, 15.0, 0.15);
}

TEST(CornerSim, VehicleStopTracksTheDemandSplit) {
  const auto s = scenario::load_scenario(source_dir() + "/config/scenarios/vehicle_stop.yaml");
  ASSERT_EQ(s.corners.size(), 4u);
  for (std::size_t c : {0u, 2u}) {
    scenario::CornerSim sim(s, c);
    const double expected = 0.9 * 40.0 * (c == 0 ? 1.0 : 0.4 / 0.6);
    for (int i = 0; i < 17000; ++i) sim.step(s.plant_dt_s);  // t = 17 s: hard braking held
    EXPECT_NEAR(sim.last().command, expected, 1e-9);
    EXPECT_NEAR(sim.last().force_internal_kN, expected, 0.3);
  }
}

// The true curve differs between 28 and 54 C by the configured amount in the recording: the
// external force near 5 rev of the paper sweep's T28 and T54 corners.
TEST(PaperRig, RecordedCurveMovesWithTemperatureByTheConfiguredAmount) {
  const auto s = scenario::load_scenario(source_dir() + "/config/scenarios/paper_rig_sweep.yaml");
  ASSERT_EQ(s.corners.size(), 14u);
  EXPECT_EQ(s.corners.front().name, "T28");
  EXPECT_EQ(s.corners.back().name, "T54");
  auto force_near = [&](std::size_t corner, double x) {
    scenario::CornerSim sim(s, corner);
    double sf = 0.0, sx = 0.0;
    int n = 0;
    for (int i = 0; i < 22000; ++i) {
      const auto& r = sim.step(s.plant_dt_s);
      if (std::abs(r.position_rev - x) < 0.01) { sf += r.force_external_kN; sx += r.position_rev; ++n; }
    }
    EXPECT_GT(n, 10);
    // Correct the bin's mean position to x with the local slope of the true curve.
    const auto& c = sim.plant().curve();
    const double T = s.corners[corner].conditions.temperature_C;
    return sf / n + c.slope_kN_per_rev(x, T, 0.0) * (x - sx / n);
  };
  const plant::ClampCurve curve(s.plant.curve);
  for (const double x : {3.0, 5.0}) {
    const double configured = curve.force_kN(x, 28.0, 0.0) - curve.force_kN(x, 54.0, 0.0);
    const double recorded = force_near(0, x) - force_near(13, x);
    EXPECT_NEAR(recorded, configured, 0.1) << "x = " << x;
    EXPECT_GT(recorded, 1.0);
  }
}

// The force loop's curve estimate never rises as the position falls: below the cubic's local
// minimum it is held at that minimum; above it, it is the cubic.
TEST(CurveEstimate, HeldAtTheCubicsLocalMinimumBelowIt) {
  // 0.2 (x - 1)^3 + 0.8 (x - 1)^2 + 2 (x - 1) + 1 has no minimum: monotone already. Stretch it:
  // a cubic fitted on [1, 6] with a minimum at x = 0.5 (slope 3a x^2 + 2b x + c = 0).
  const scenario::CurveEstimate none{0.2, 0.0, 2.0, 1.0};
  EXPECT_EQ(none.local_min_rev(), -std::numeric_limits<double>::infinity());
  EXPECT_DOUBLE_EQ(none.force_kN(-0.7), none.cubic_kN(-0.7));
  const double a = 0.1, b = 0.9, x_m = 0.5;
  const double c = -(3.0 * a * x_m * x_m + 2.0 * b * x_m);  // slope 0 at x_m, rising after
  const scenario::CurveEstimate rising_below{a, b, c, 0.3};
  EXPECT_NEAR(rising_below.local_min_rev(), x_m, 1e-12);
  EXPECT_GT(rising_below.cubic_kN(-0.8), rising_below.cubic_kN(x_m) + 0.5);  // the raw cubic rises
  double prev = -std::numeric_limits<double>::infinity();
  for (double x = -0.8; x <= 6.0; x += 0.01) {
    const double f = rising_below.force_kN(x);
    EXPECT_GE(f, prev - 1e-12) << x;  // rounding at the minimum
    prev = f;
    if (x >= x_m) {
      EXPECT_DOUBLE_EQ(f, rising_below.cubic_kN(x)) << x;
    }
  }
  // The least value over an interval (the CCU's curve estimate below the trusted range): at an
  // end or at the local minimum, as a fine grid finds it.
  const bbw::model::Curve m{a, b, c, 0.3};
  for (const auto& [lo, hi] : {std::pair{-0.8, 1.0}, std::pair{0.6, 2.0}, std::pair{-0.8, 0.2}}) {
    double grid = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= 10000; ++k) grid = std::min(grid, m.force_kN(lo + (hi - lo) * k / 10000.0));
    EXPECT_NEAR(m.least_kN(lo, hi), grid, 1e-6) << lo << " " << hi;
  }
  // A quadratic (a = 0) with its minimum at -c / 2b, and a concave one without.
  EXPECT_DOUBLE_EQ((scenario::CurveEstimate{0.0, 1.0, -2.0, 0.0}.local_min_rev()), 1.0);
  EXPECT_EQ((scenario::CurveEstimate{0.0, -1.0, 2.0, 0.0}.local_min_rev()), -std::numeric_limits<double>::infinity());
  // a < 0: the minimum is the smaller stationary point.
  const scenario::CurveEstimate falling_cubic{-0.1, 0.9, -0.6, 0.0};
  const double xm = falling_cubic.local_min_rev();
  EXPECT_NEAR(3 * -0.1 * xm * xm + 2 * 0.9 * xm - 0.6, 0.0, 1e-12);
  EXPECT_GT(6 * -0.1 * xm + 2 * 0.9, 0.0);
}

// A corner on curve feedback, started released below the curve's minimum where the raw cubic
// reads more than the command: it applies to the command instead of releasing onto its stop;
// below the cubic's least value it finds the command on the end-of-line curve scaled to meet
// the cubic there (this scenario's caliper is its own end-of-line caliper).
TEST(CornerSim, CurveFeedbackBelowTheCubicsMinimumFollowsTheEndOfLineCurve) {
  const auto s = scenario::load_scenario(source_dir() + "/config/scenarios/vehicle_stop.yaml");
  scenario::CornerSim sim(s, 0);  // a demand drive: starts released, at 0 rev
  ASSERT_NEAR(sim.last().position_true_rev, 0.0, 1e-9);
  const plant::ClampCurve eol(s.plant.curve);
  const double temperature_C = s.corners[0].conditions.temperature_C;
  // A cubic with its minimum at 1.6 rev, 10 % above the end-of-line curve there (as tuning seed
  // 1403 run 646's), rising to 12 kN at the released home: on the raw cubic any command below
  // 12 kN reads as too much force at 0 rev.
  const double a = 0.4, b = 1.2, x_m = 1.6, scale = 1.1;
  const double c = -(3.0 * a * x_m * x_m + 2.0 * b * x_m);
  const double d = scale * eol.force_kN(x_m, temperature_C, 0.0) - ((a * x_m + b) * x_m + c) * x_m;
  scenario::ExternalInputs ext;
  ext.curve = scenario::CurveEstimate{a, b, c, d};
  ASSERT_GT(ext.curve->cubic_kN(0.0), 10.0);
  ext.feedback = corner_unit::ForceFeedback::Curve;
  ext.force_command_kN = 8.0;
  for (int i = 0; i < 2000; ++i) sim.step(s.plant_dt_s, ext);
  EXPECT_GT(sim.last().position_true_rev, x_m);
  EXPECT_NEAR(ext.curve->cubic_kN(sim.last().position_rev), 8.0, 0.3);
  // A command below the cubic's least value (4.1 kN): found on the scaled end-of-line curve.
  ext.force_command_kN = 2.5;
  for (int i = 0; i < 2000; ++i) sim.step(s.plant_dt_s, ext);
  EXPECT_GT(sim.last().position_true_rev, s.plant.curve.contact_rev);
  EXPECT_LT(sim.last().position_true_rev, x_m);
  EXPECT_NEAR(sim.last().force_true_kN, 2.5 / scale, 0.3);
}

// A force loop whose feedback reads more than any command (a load cell 6 kN high) releases to
// the released home and stays there (controller.force_home_limit); without the limit it drove
// the actuator onto the plant's retracted stop and pushed there at the current limit.
TEST(CornerSim, AForceLoopReadingTooMuchStopsAtTheReleasedHome) {
  struct High : scenario::SensorHook {
    void apply(plant::Measurement& m) override { m.force_internal_kN += 6.0; }
  };
  auto s = scenario::load_scenario(source_dir() + "/config/scenarios/vehicle_stop.yaml");
  const auto run = [&](bool limit) {
    s.controller.force_home_limit = limit;
    scenario::CornerSim sim(s, 0);
    High high;
    scenario::ExternalInputs ext;
    ext.sensor_hook = &high;
    ext.feedback = corner_unit::ForceFeedback::LoadCell;
    ext.force_command_kN = 2.0;
    double lowest_rev = 0.0, last_A = 0.0;
    for (int i = 0; i < 1000; ++i) {
      const auto& k = sim.step(s.plant_dt_s, ext);
      lowest_rev = std::min(lowest_rev, k.position_true_rev);
      last_A = k.current_command_A;
    }
    return std::pair{lowest_rev, last_A};
  };
  const auto [limited_rev, limited_A] = run(true);
  EXPECT_GT(limited_rev, s.controller.release_position_rev - s.controller.force_home_margin_rev - 0.05);
  EXPECT_LT(std::abs(limited_A), 5.0);
  const auto [free_rev, free_A] = run(false);
  EXPECT_NEAR(free_rev, s.plant.transmission.retracted_stop_rev, 1e-6);
  EXPECT_LT(free_A, -30.0);
}

// A corner holding 35 kN on its load cell, which then reads 1.5 kN low, is moved 5 ms later to
// curve feedback (the CCU's reaction to the load-cell fault) with a curve that reads 13 % high (tune_bias run 94: 4.7 kN at 37 kN), then
// released to 3 kN. With controller.feedback_switch_restart the loop restarts its stiffness
// estimate and force integral at the switch and the release stops on the pads. Without it the
// 6 kN step at the switch, after the loop had pushed on 1 thousandth of a rev, read as a caliper 80 times stiffer: the loop released
// at a fraction of a rev per second, wound its force integral, and that integral carried the
// release behind the pads' contact at the speed limit.
TEST(CornerSim, AFeedbackSwitchRestartsTheForceLoopsStiffnessAndIntegral) {
  auto s = scenario::load_scenario(source_dir() + "/config/scenarios/vehicle_stop.yaml");
  ASSERT_TRUE(s.controller.feedback_switch_restart);
  const plant::ClampCurve eol(s.plant.curve);
  const double temperature_C = s.corners[0].conditions.temperature_C;
  // The cubic through 1.13 x the end-of-line curve at four positions from 1 rev to past the hold.
  const double contact_rev = eol.contact_rev(temperature_C, 0.0);
  Eigen::Matrix4d v;
  Eigen::Vector4d f;
  for (int i = 0; i < 4; ++i) {
    const double x = contact_rev + 1.0 + 2.0 * i;
    v.row(i) << x * x * x, x * x, x, 1.0;
    f(i) = 1.13 * eol.force_kN(x, temperature_C, 0.0);
  }
  const Eigen::Vector4d coef = v.colPivHouseholderQr().solve(f);
  const scenario::CurveEstimate high{coef(0), coef(1), coef(2), coef(3)};
  struct Biased : scenario::SensorHook {
    void apply(plant::Measurement& m) override { m.force_internal_kN -= 1.5; }
  };
  const auto run = [&](bool restart) {
    s.controller.feedback_switch_restart = restart;
    scenario::CornerSim sim(s, 0);
    scenario::ExternalInputs ext;
    ext.curve = high;
    ext.feedback = corner_unit::ForceFeedback::LoadCell;
    ext.force_command_kN = 35.0;
    for (int i = 0; i < 1000; ++i) sim.step(s.plant_dt_s, ext);
    const double held_kN = sim.last().force_true_kN;
    // The load cell's bias the CCU reacts to: the loop pushes on for the 5 ms until the switch.
    Biased low;
    ext.sensor_hook = &low;
    for (int i = 0; i < 5; ++i) sim.step(s.plant_dt_s, ext);
    ext.feedback = corner_unit::ForceFeedback::Curve;
    for (int i = 0; i < 300; ++i) sim.step(s.plant_dt_s, ext);
    double lowest_rev = 1e9;
    for (int i = 0; i < 600; ++i) {
      ext.force_command_kN = std::max(3.0, 35.0 - 0.32 * i);  // 320 kN/s down to 3 kN
      lowest_rev = std::min(lowest_rev, sim.step(s.plant_dt_s, ext).position_true_rev);
    }
    return std::tuple{held_kN, lowest_rev, sim.last().force_true_kN};
  };
  const auto [held_kN, lowest_rev, end_kN] = run(true);
  std::cout << "[ MEASURED ] with the restart: held " << held_kN << " kN, lowest " << lowest_rev << " rev (contact "
            << contact_rev << "), end " << end_kN << " kN" << std::endl;
  EXPECT_NEAR(held_kN, 35.0, 1.0);  // the load cell reads the keys' friction too
  EXPECT_GT(lowest_rev, contact_rev);
  EXPECT_NEAR(end_kN, 3.0 / 1.13, 0.5);
  const auto [held_off_kN, lowest_off_rev, end_off_kN] = run(false);
  std::cout << "[ MEASURED ] without: lowest " << lowest_off_rev << " rev, end " << end_off_kN << " kN" << std::endl;
  EXPECT_LT(lowest_off_rev, contact_rev - 0.3);
}

// A cubic without a local minimum that reads 2 kN at the released home (a line, 2 + 3 x): below
// controller.curve_trusted_min_rev (1 rev) the end-of-line curve scaled to meet it takes over, and
// a 1 kN command puts the pads on the disc. On the raw line the loop looked for 1 kN behind the
// home, with the pads off.
TEST(CornerSim, CurveFeedbackBelowTheTrustedPositionFollowsTheEndOfLineCurve) {
  const auto s = scenario::load_scenario(source_dir() + "/config/scenarios/vehicle_stop.yaml");
  ASSERT_DOUBLE_EQ(s.controller.curve_trusted_min_rev, 1.0);
  scenario::CornerSim sim(s, 0);
  scenario::ExternalInputs ext;
  ext.curve = scenario::CurveEstimate{0.0, 0.0, 3.0, 2.0};
  ASSERT_EQ(ext.curve->local_min_rev(), -std::numeric_limits<double>::infinity());
  ext.feedback = corner_unit::ForceFeedback::Curve;
  ext.force_command_kN = 1.0;
  for (int i = 0; i < 2000; ++i) sim.step(s.plant_dt_s, ext);
  EXPECT_GT(sim.last().position_true_rev, s.plant.curve.contact_rev);
  EXPECT_GT(sim.last().force_true_kN, 0.1);
  EXPECT_LT(sim.last().force_true_kN, 1.0);
}
