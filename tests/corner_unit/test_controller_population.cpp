// The local force loop on the tuning population's calipers (issue 14): after a reversal the key
// friction sticks and the load cell is 10-100x stiffer against position than the clamp curve.
// With the nominal slope alone the loop's gain is that much too high and it limit-cycles
// (current bang-bang at the limit, the load cell stepping kN within milliseconds: tuning member
// 13 raised load_cell_noisy in every campaign run it drove); with the slope it sees in its own
// feedback (ControllerParams::stiffness_estimate) it holds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "bbw/corner_unit/controller.hpp"
#include "bbw/plant/plant.hpp"
#include "bbw/scenario/population.hpp"
#include "bbw/scenario/scenario.hpp"

using namespace bbw;

namespace {

constexpr double kDt = 1e-3;

const scenario::PopulationSpec& tuning() {
  static const auto spec = scenario::load_population_spec(BBW_SOURCE_DIR "/config/population/tuning.yaml");
  return spec;
}

// Piecewise-linear force command (t, kN) with its rate as feedforward, as a CCU sends it.
using Profile = std::vector<std::pair<double, double>>;

struct HoldStats {
  double load_cell_hp_rms_kN = 0.0;  // RMS of the load cell high-passed (20 ms) in the holds
  double current_hp_rms_A = 0.0;     // RMS of the motor current high-passed (20 ms) in the holds
  int current_limit_steps = 0;       // steps at the current limit in the holds
};

HoldStats run(const plant::PlantParams& pp, const Profile& profile, bool stiffness_estimate, double temperature_C = 40.0) {
  corner_unit::ControllerParams cp;
  cp.actuator = scenario::actuator_model(pp);
  cp.current_limit_A = pp.motor.current_limit_A;
  cp.stiffness_estimate = stiffness_estimate;
  corner_unit::LocalController ctl(cp);
  plant::Conditions c;
  c.temperature_C = temperature_C;
  plant::Plant plant(pp, {}, c, 7);
  plant.reset(0.0);
  HoldStats h;
  double lc_lp = 0.0, i_lp = 0.0, sum2 = 0.0, sum_i2 = 0.0, n = 0.0;
  const double end = profile.back().first;
  for (double t = kDt; t <= end + 1e-9; t += kDt) {
    std::size_t k = 1;
    while (k + 1 < profile.size() && profile[k].first < t) ++k;
    const auto [t0, f0] = profile[k - 1];
    const auto [t1, f1] = profile[k];
    const double rate = (f1 - f0) / (t1 - t0);
    const double cmd = f0 + rate * (t - t0);
    const auto& m = plant.measurement();
    corner_unit::ControllerInputs in{m.position_rev, m.speed_rev_per_s, m.force_internal_kN, m.force_internal_kN};
    const auto out = ctl.update_force(cmd, in, kDt, rate);
    plant.step({out.current_command_A}, kDt);
    lc_lp += -std::expm1(-kDt / 0.02) * (m.force_internal_kN - lc_lp);
    i_lp += -std::expm1(-kDt / 0.02) * (plant.state().current_A - i_lp);
    // A hold: the segment is flat and began at least 0.3 s ago.
    if (f0 == f1 && cmd > 1.0 && t - t0 >= 0.3) {
      sum2 += (m.force_internal_kN - lc_lp) * (m.force_internal_kN - lc_lp);
      n += 1.0;
      sum_i2 += (plant.state().current_A - i_lp) * (plant.state().current_A - i_lp);
      if (std::abs(out.current_command_A) >= cp.current_limit_A - 1e-9) ++h.current_limit_steps;
    }
  }
  h.load_cell_hp_rms_kN = std::sqrt(sum2 / std::max(n, 1.0));
  h.current_hp_rms_A = std::sqrt(sum_i2 / std::max(n, 1.0));
  return h;
}

// The ramps of tune run 15 (member 13, where FL limit-cycled at the reversal near 1.5 s), then
// holds approached from above and from below, at low, middle and high force.
const Profile kReversals = {{0.0, 0.0},  {1.0, 24.0}, {1.5, 4.0},  {2.0, 13.0}, {3.0, 13.0}, {3.2, 2.0},
                            {4.2, 2.0},  {4.4, 22.0}, {5.4, 22.0}, {5.6, 30.0}, {5.8, 20.0}, {6.8, 20.0}};

}  // namespace

TEST(ForceLoopOnThePopulation, TuningMember13HoldsWhereItLimitCycled) {
  const plant::PlantParams pp = scenario::population_member(tuning(), 13).params;
  const HoldStats with = run(pp, kReversals, true);
  const HoldStats without = run(pp, kReversals, false);
  // Without the seen stiffness: the limit cycle (this is what the fix is for).
  EXPECT_GT(without.current_limit_steps, 100);
  EXPECT_GT(without.load_cell_hp_rms_kN, 0.5);
  // With it: never at the current limit in a hold, the load cell as quiet as its noise.
  EXPECT_EQ(with.current_limit_steps, 0);
  EXPECT_LT(with.load_cell_hp_rms_kN, 0.1);
  EXPECT_LT(with.current_hp_rms_A, 3.0);
  std::printf("member 13 in holds: without: %d steps at the current limit, load cell %.3f kN high-passed RMS, "
              "current %.2f A high-passed RMS; with: %d, %.3f kN, %.2f A\n",
              without.current_limit_steps, without.load_cell_hp_rms_kN, without.current_hp_rms_A, with.current_limit_steps,
              with.load_cell_hp_rms_kN, with.current_hp_rms_A);
}

TEST(ForceLoopOnThePopulation, EveryTuningCaliperHoldsAtEveryTemperature) {
  for (int i = 0; i < tuning().count; ++i) {
    const plant::PlantParams pp = scenario::population_member(tuning(), i).params;
    for (const double temperature_C : {28.0, 54.0}) {
      const HoldStats h = run(pp, kReversals, true, temperature_C);
      EXPECT_LT(h.load_cell_hp_rms_kN, 0.1) << "member " << i << " at " << temperature_C << " C";
      // (measurement noise through the loop: 0.1-2.2 A; the limit cycle: 25 A)
      EXPECT_LT(h.current_hp_rms_A, 3.0) << "member " << i << " at " << temperature_C << " C";
      EXPECT_EQ(h.current_limit_steps, 0) << "member " << i << " at " << temperature_C << " C";
    }
  }
}
