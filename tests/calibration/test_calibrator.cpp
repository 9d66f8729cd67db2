#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/model/friction_tracker.hpp"
#include "bbw/model/delay_line.hpp"
#include "bbw/calibration/offline.hpp"
#include "synthetic.hpp"

using namespace bbw::calibration;
using bbw::calibration::test::SyntheticTruth;
using bbw::calibration::test::synthetic_recording;

namespace {

CalibratorConfig base_config(Mode mode) {
  CalibratorConfig c;
  c.mode = mode;
  c.elements_M = 6;
  c.samples_L = 64;
  c.pf_points_N = 20;
  c.start_lag_n0 = 10;
  c.delta_max_rev = 0.3;
  c.x_min_rev = 0.5;
  c.x_max_rev = 6.0;
  c.f_min_kN = 0.0;
  c.f_max_kN = 40.0;
  c.initial_curve = Curve{0.0, 0.5, 1.0, 0.0};  // deliberately wrong
  return c;
}

SyntheticTruth truth_for(const CalibratorConfig& c) {
  SyntheticTruth t;
  t.delta_rev.resize(static_cast<std::size_t>(c.elements_M));
  thresholds(t.delta_rev.size(), c.delta_max_rev,
             c.mode == Mode::Robust && c.spacing == ThresholdSpacing::Geometric, c.geometric_ratio,
             t.delta_rev.data());
  for (std::size_t i = 0; i < t.delta_rev.size(); ++i) t.k_kN_per_rev.push_back(0.15 / t.delta_rev[i]);  // 0.15 kN each
  return t;
}

}  // namespace

TEST(Calibrator, DefaultConfigIsValid) { EXPECT_NO_THROW(CalibratorConfig{}.validate()); }

TEST(Calibrator, RejectsBadConfigNamingTheField) {
  CalibratorConfig c;
  c.samples_L = 5;
  try {
    Calibrator cal(c);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("samples_L = 5"), std::string::npos) << e.what();
  }
}

TEST(Calibrator, RobustRecoversItsOwnModelExactly) {
  auto c = base_config(Mode::Robust);
  c.ridge = 0.0;  // exact data: no regularisation needed
  const auto truth = truth_for(c);
  const auto rec = synthetic_recording(truth, 0.0, 1);
  const auto res = run_recording(c, rec);
  EXPECT_GE(res.stats.fits_accepted, 8u);
  EXPECT_LT(res.score.max_abs_error_kN, 1e-6);
  for (std::size_t i = 0; i < truth.k_kN_per_rev.size(); ++i) {
    EXPECT_NEAR(res.friction.stiffness_kN_per_rev[i], truth.k_kN_per_rev[i], 1e-4 * truth.k_kN_per_rev[i]);
  }
  // The curve converges over the whole PF range once a full-range cycle has been fitted.
  for (double x = 0.5; x <= 6.0; x += 0.25) EXPECT_NEAR(res.curve.force_kN(x), truth.curve.force_kN(x), 1e-6);
}

TEST(Calibrator, PaperModeRecoversItsOwnModelWithoutNoise) {
  const auto c = base_config(Mode::Paper);
  const auto truth = truth_for(c);
  const auto rec = synthetic_recording(truth, 0.0, 1);
  const auto res = run_recording(c, rec);
  EXPECT_GE(res.stats.fits_accepted, 8u);
  // Not exact even on its own model: replaying the elements over thinned samples misses
  // reversal points (the last cycle then fits a negative K_i), and PF points at the range
  // ends are never refreshed because a start is detected after the turning point.
  EXPECT_LT(res.score.max_abs_error_kN, 0.25);
  EXPECT_GT(res.score.max_abs_error_kN, 1e-3);
  double initial_err = 0.0, final_err = 0.0;
  for (double x = 1.0; x <= 5.0; x += 0.25) {  // interior: the end PF points are never refreshed
    initial_err = std::max(initial_err, std::fabs(c.initial_curve.force_kN(x) - truth.curve.force_kN(x)));
    final_err = std::max(final_err, std::fabs(res.curve.force_kN(x) - truth.curve.force_kN(x)));
  }
  EXPECT_LT(final_err, initial_err / 4.0);
}

TEST(Calibrator, RejectsCorruptSamplesAndCountsThem) {
  Calibrator cal(base_config(Mode::Robust));
  EXPECT_TRUE(cal.update({0.0, 1.0, 2.0}).valid);
  EXPECT_FALSE(cal.update({0.001, std::nan(""), 2.0}).valid);
  EXPECT_FALSE(cal.update({0.002, 1.0, INFINITY}).valid);
  EXPECT_FALSE(cal.update({0.003, 1.0, 1e6}).valid);   // out of the physical range
  EXPECT_FALSE(cal.update({0.0, 1.0, 2.0}).valid);     // time going backwards
  EXPECT_TRUE(cal.update({0.004, 1.0, 2.0}).valid);
  EXPECT_EQ(cal.stats().samples_rejected, 4u);
  EXPECT_EQ(cal.stats().samples_seen, 6u);
}

TEST(Calibrator, NoisyCorruptedStreamNeverReachesTheFit) {
  // Same recording with every 97th sample corrupted: the fit must equal the clean one's, since
  // corrupt samples are dropped before the detector, the elements and the store.
  const auto c = base_config(Mode::Robust);
  const auto truth = truth_for(c);
  auto rec = synthetic_recording(truth, 0.03, 5, 12.0);
  Calibrator clean(c), dirty(c);
  for (std::size_t k = 0; k < rec.time_s.size(); ++k) {
    clean.update({rec.time_s[k], rec.position_rev[k], rec.force_kN[k]});
    if (k % 97 == 0) dirty.update({rec.time_s[k] - 1e-4, std::nan(""), rec.force_kN[k]});
    dirty.update({rec.time_s[k], rec.position_rev[k], rec.force_kN[k]});
  }
  EXPECT_EQ(dirty.stats().fits_accepted, clean.stats().fits_accepted);
  EXPECT_DOUBLE_EQ(dirty.curve().a, clean.curve().a);
  EXPECT_DOUBLE_EQ(dirty.friction().stiffness_kN_per_rev[2], clean.friction().stiffness_kN_per_rev[2]);
  EXPECT_GT(dirty.stats().samples_rejected, 100u);
}

TEST(Calibrator, StateFitsTheMemoryBudgetAtPaperSize) {
  CalibratorConfig c = base_config(Mode::Robust);
  c.elements_M = 8;
  c.samples_L = 64;
  c.pf_points_N = 20;
  Calibrator cal(c);
  EXPECT_LE(cal.state_bytes(), 16u * 1024u) << cal.state_bytes();
  EXPECT_GT(cal.state_bytes(), 65u * 10u * 8u);  // at least the store itself
  // With both optional effect terms (a 13th parameter and the delay line, sized for 2.5 kHz).
  c.viscous_friction = true;
  c.force_delay_s = 0.005;
  Calibrator with_effects(c);
  EXPECT_LE(with_effects.state_bytes(), 16u * 1024u) << with_effects.state_bytes();
  EXPECT_GT(with_effects.state_bytes(),
            cal.state_bytes() + 2u * (CalibratorConfig::force_delay_slots(0.005) - 2u) * sizeof(double));
  EXPECT_EQ(CalibratorConfig::force_delay_slots(0.005), 16u);
  EXPECT_EQ(CalibratorConfig::force_delay_slots(0.05), 128u);
  EXPECT_EQ(CalibratorConfig::force_delay_slots(0.0), 2u);
}

TEST(Calibrator, ResetCurveRestartsFromGivenCurve) {
  Calibrator cal(base_config(Mode::Robust));
  cal.reset_curve(Curve{0.0, 0.0, 2.0, 1.0});
  EXPECT_DOUBLE_EQ(cal.curve().force_kN(2.0), 5.0);
  EXPECT_DOUBLE_EQ(cal.pf_forces_kN().front(), 2.0 * 0.5 + 1.0);
}

// Backlash term, worked by hand: width 0.05 rev (half 0.025). The spindle starts at the first
// position and is dragged along only once the resolver is half the play away from it.
TEST(Calibrator, BacklashTermRunsTheModelOnTheSpindlePosition) {
  auto c = base_config(Mode::Robust);
  c.initial_curve = Curve{0.0, 0.0, 10.0, 0.0};  // C(x) = 10 x kN
  c.backlash_width_rev = 0.05;
  Calibrator cal(c);
  const double x[] = {1.0, 1.1, 1.2, 1.19, 1.18, 1.14, 1.3};
  const double spindle[] = {1.0, 1.075, 1.175, 1.175, 1.175, 1.165, 1.275};
  for (int k = 0; k < 7; ++k) {
    const Estimate e = cal.update({0.001 * (k + 1), x[k], 5.0});
    ASSERT_TRUE(e.valid);
    EXPECT_NEAR(e.curve_force_kN, 10.0 * spindle[k], 1e-12) << "sample " << k;
  }
  // Off: the curve is read at the resolver position.
  c.backlash_width_rev = 0.0;
  Calibrator plain(c);
  EXPECT_NEAR(plain.update({0.001, 1.19, 5.0}).curve_force_kN, 11.9, 1e-12);
}

// A calibrator restarted with fitted stiffnesses (a corner's last good snapshot) reports its
// friction as fitted once every element's state is known (the position swept 2 Delta_max), not
// before; one given stiffnesses that were not fitted does not, until a fit of its own.
TEST(Calibrator, RestartedWithFittedStiffnessesItsFrictionIsFittedOnceItsStatesAreKnown) {
  const auto c = base_config(Mode::Robust);
  Calibrator restarted(c), unfitted(c);
  const std::vector<double> k(6, 2.0);
  restarted.set_friction_stiffness(k, true);
  unfitted.set_friction_stiffness(k);
  int j = 1;
  for (; j <= 50; ++j) {  // 2 rev up by 0.5 * 2 Delta_max: not yet swept
    const double x = 2.0 + 0.003 * j;
    EXPECT_FALSE(restarted.update({0.001 * j, x, 10.0}).friction_fitted) << "x " << x;
  }
  bool fitted_seen = false;
  for (; j <= 400; ++j) {  // on up, past 2 Delta_max = 0.6 rev
    const double x = 2.0 + 0.003 * j;
    const Estimate e = restarted.update({0.001 * j, x, 10.0});
    const Estimate u = unfitted.update({0.001 * j, x, 10.0});
    EXPECT_FALSE(e.calibrated);
    EXPECT_FALSE(u.friction_fitted);
    fitted_seen = fitted_seen || e.friction_fitted;
    if (x >= 2.0 + 2.0 * c.delta_max_rev + 0.01) {
      EXPECT_TRUE(e.friction_fitted) << "x " << x;
    }
  }
  EXPECT_TRUE(fitted_seen);
}

// Friction stiffnesses measured elsewhere (a caliper's end-of-line keys) held as the friction
// memory's prior: cycles that modulate within 0.06 rev turn only the smallest elements round and
// cannot tell the larger ones' friction from the curve. Without a prior (weight 0) their first fit
// sets the amplitudes from what they could tell; with one, the measured keys stay where the cycles
// had nothing to say, and the estimate follows the clamp force. Both report the friction as fitted
// once the states are known.
TEST(Calibrator, AFrictionPriorHoldsTheKeysThatNarrowCyclesCannotTell) {
  auto c = base_config(Mode::Robust);
  c.friction_memory = 0.9;
  c.min_cycle_span_rev = 0.05;
  const auto truth = truth_for(c);  // 0.15 kN on each of 6 elements, 0.3 rev down
  Calibrator none(c), prior(c);
  none.set_friction_prior(truth.k_kN_per_rev, 0.0);
  prior.set_friction_prior(truth.k_kN_per_rev, 1000.0);
  EXPECT_TRUE(prior.prior_friction_fitted());
  std::vector<double> pos(truth.delta_rev.size(), 0.5);  // relaxed at 0.5 rev, as the calibrators assume
  double worst_none_kN = 0.0, worst_prior_kN = 0.0;
  const double dt = 0.001;
  for (int k = 0; k < 14000; ++k) {
    const double t = dt * k;
    // Up to 3 rev in 2 s (every state known), then +/- 0.03 rev at 5 Hz.
    const double x = t < 2.0 ? 0.5 + 1.25 * t : 3.0 + 0.03 * std::sin(2.0 * M_PI * 5.0 * (t - 2.0));
    const double fric = bbw::model::elements_step(x, truth.delta_rev.data(), pos.data(), pos.size(),
                                                  truth.k_kN_per_rev.data(), nullptr);
    const double f_true = truth.curve.force_kN(x);
    const Estimate a = none.update({t, x, f_true + fric});
    const Estimate b = prior.update({t, x, f_true + fric});
    if (t > 8.0) {
      worst_none_kN = std::max(worst_none_kN, std::abs(a.force_kN - f_true));
      worst_prior_kN = std::max(worst_prior_kN, std::abs(b.force_kN - f_true));
      EXPECT_TRUE(a.friction_fitted && b.friction_fitted);
    }
  }
  ASSERT_GE(none.stats().fits_accepted, 20u);
  ASSERT_GE(prior.stats().fits_accepted, 20u);
  double amplitude_none_kN = 0.0, amplitude_prior_kN = 0.0;
  for (std::size_t i = 0; i < truth.delta_rev.size(); ++i) {
    amplitude_none_kN += none.friction().stiffness_kN_per_rev[i] * truth.delta_rev[i];
    amplitude_prior_kN += prior.friction().stiffness_kN_per_rev[i] * truth.delta_rev[i];
  }
  std::printf("keys 0.90 kN wide: %.3f kN fitted with the prior (worst estimate error %.3f kN), %.3f without (%.3f)\n",
              amplitude_prior_kN, worst_prior_kN, amplitude_none_kN, worst_none_kN);
  EXPECT_NEAR(amplitude_prior_kN, 0.9, 0.1);
  EXPECT_LT(worst_prior_kN, 0.5 * worst_none_kN);
  EXPECT_THROW(prior.set_friction_prior(truth.k_kN_per_rev, -1.0), std::invalid_argument);
}

// The delay line's newest value strictly before a time (what a resolver finding freezes: the
// friction of the last sample before the fault's onset), no interpolation; the oldest kept when
// every kept sample is newer; 0 when empty.
TEST(DelayLine, NewestBeforeIsTheLastSampleOlderThanTheTime) {
  bbw::model::DelayLine d(3);
  EXPECT_EQ(d.newest_before(1.0), 0.0);
  for (int k = 1; k <= 4; ++k) d.push(0.001 * k, 10.0 * k);  // keeps 2, 3, 4 ms: 20, 30, 40
  EXPECT_EQ(d.newest_before(0.0035), 30.0);
  EXPECT_EQ(d.newest_before(0.004), 30.0);  // strictly before
  EXPECT_EQ(d.newest_before(1.0), 40.0);
  EXPECT_EQ(d.newest_before(0.001), 20.0);  // older than all kept: the oldest
}

// Load-dependent friction term: with the same stiffnesses, the friction estimate is the plain
// one times 1 + g max(C(x), 0) / F_ref, C the current curve.
TEST(Calibrator, LoadFrictionTermScalesTheFrictionWithTheCurveForce) {
  auto c = base_config(Mode::Robust);
  c.initial_curve = Curve{0.0, 0.0, 10.0, -10.0};  // C(x) = 10 (x - 1) kN: negative below 1 rev
  Calibrator plain(c);
  c.load_friction_gain = 0.8;
  c.load_friction_reference_kN = 40.0;
  Calibrator loaded(c);
  const std::vector<double> k(6, 2.0);
  plain.set_friction_stiffness(k);
  loaded.set_friction_stiffness(k);
  int checked = 0;
  for (int j = 0; j < 400; ++j) {
    const double x = 2.0 + 1.5 * std::sin(0.02 * j);  // 0.5 .. 3.5 rev, both directions
    const Estimate a = plain.update({0.001 * (j + 1), x, 20.0});
    const Estimate b = loaded.update({0.001 * (j + 1), x, 20.0});
    const double scale = 1.0 + 0.8 * std::max(10.0 * (x - 1.0), 0.0) / 40.0;
    EXPECT_NEAR(b.friction_kN, a.friction_kN * scale, 1e-9) << "x " << x;
    EXPECT_NEAR(b.force_kN, 20.0 - b.friction_kN, 1e-12);
    checked += std::fabs(a.friction_kN) > 0.1 ? 1 : 0;
  }
  EXPECT_GT(checked, 100);  // the friction was not zero throughout
}

// A corner replays the CCU's friction model with FrictionTracker: with the same parameters and
// the same position and temperature history it gives the calibrator's own estimate (no fit
// happens here: one minimum, so no cycle ends).
TEST(FrictionTracker, GivesTheCalibratorsFrictionEstimate) {
  auto c = base_config(Mode::Robust);
  c.initial_curve = Curve{0.0, 0.5, 4.0, -3.0};
  c.backlash_width_rev = 0.04;
  c.load_friction_gain = 0.7;
  c.load_friction_reference_kN = 30.0;
  c.load_cell_offset_kN_per_C = -0.03;
  c.load_cell_offset_reference_C = 35.0;
  Calibrator cal(c);
  std::vector<double> k;
  for (double d : cal.friction().delta_rev) k.push_back(0.2 / d);
  cal.set_friction_stiffness(k);
  FrictionModel m;
  m.delta_rev = cal.friction().delta_rev;
  m.stiffness_kN_per_rev = k;
  m.load_gain = 0.7;
  m.load_reference_kN = 30.0;
  m.backlash_width_rev = 0.04;
  m.curve = c.initial_curve;  // the curve the calibrator scales its friction along
  m.load_cell_offset_kN_per_C = -0.03;
  m.load_cell_offset_reference_C = 35.0;
  FrictionTracker tracker;
  double max_friction = 0.0;
  for (int j = 0; j < 3000; ++j) {
    // up 1 -> 3 rev, down to 2, up to 2.5, with a small ripple that stays inside the play
    const double t = 0.001 * j;
    const double x = (j < 1000 ? 1.0 + 2.0 * t : j < 2000 ? 3.0 - (t - 1.0) : 2.0 + 0.5 * (t - 2.0)) +
                     0.01 * std::sin(40.0 * t);
    if (!tracker.started()) tracker.reset(m.delta_rev.size(), x);
    // Temperature from 30 to 60 C, missing on every 7th sample.
    const double temp_C = j % 7 == 3 ? std::nan("") : 30.0 + 0.01 * j;
    const Estimate e = cal.update({t + 0.001, x, 10.0, std::nan(""), temp_C});
    ASSERT_TRUE(e.valid);
    // The load cell minus what the tracker says it holds beyond the clamp force is f_hat.
    EXPECT_NEAR(10.0 - tracker.step_load_cell_excess(m, x, 0.0, temp_C), e.force_kN, 1e-12) << "sample " << j;
    max_friction = std::max(max_friction, std::fabs(e.friction_kN));
  }
  EXPECT_EQ(cal.stats().fits_accepted + cal.stats().fits_rejected, 0u);
  EXPECT_GT(max_friction, 0.5);  // the elements did slip and load: the comparison means something
}

// Load-cell thermal offset term: k (T - T_ref) comes off every reading before the model; a
// sample without a temperature uses the last one (the reference before any).
TEST(Calibrator, LoadCellOffsetTermRemovesTheThermalZeroDrift) {
  auto c = base_config(Mode::Robust);
  c.load_cell_offset_kN_per_C = 0.02;
  c.load_cell_offset_reference_C = 40.0;
  Calibrator cal(c);
  const double nan = std::nan("");
  EXPECT_NEAR(cal.update({0.001, 1.0, 10.0, nan, nan}).force_kN, 10.0, 1e-12);   // none yet: T_ref
  EXPECT_NEAR(cal.update({0.002, 1.0, 10.0, nan, 50.0}).force_kN, 9.8, 1e-12);   // 0.02 x 10 C
  EXPECT_NEAR(cal.update({0.003, 1.0, 10.0, nan, nan}).force_kN, 9.8, 1e-12);    // the last one
  EXPECT_NEAR(cal.update({0.004, 1.0, 10.0, nan, 30.0}).force_kN, 10.2, 1e-12);  // below T_ref
  c.load_cell_offset_kN_per_C = 0.0;
  Calibrator plain(c);
  EXPECT_NEAR(plain.update({0.001, 1.0, 10.0, nan, 50.0}).force_kN, 10.0, 1e-12);  // off
}
