// Accuracy against truth on recordings the plant makes (the paper's rig, 14 temperatures).
// The calibrator's settings (config/calibrator/robust.yaml) were chosen on a different caliper
// (config/scenarios/tuning/); these recordings were not used to choose them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/calibration/fusion.hpp"
#include "rig_recording.hpp"

using namespace bbw::calibration;
using bbw::calibration::test::source_path;

namespace {

const bbw::scenario::Scenario& sweep() {
  static const auto sc = bbw::scenario::load_scenario(source_path("config/scenarios/paper_rig_sweep.yaml"));
  return sc;
}

}  // namespace

TEST(CalibratorAccuracy, RobustWorstCaseAtEveryTemperatureMeetsTarget) {
  const auto robust = load_config(source_path("config/calibrator/robust.yaml"));
  const auto paper = load_config(source_path("config/calibrator/paper.yaml"));
  const auto& sc = sweep();
  ASSERT_EQ(sc.corners.size(), 14u);
  double worst_robust = 0.0;
  for (std::size_t i = 0; i < sc.corners.size(); ++i) {
    ASSERT_GE(sc.corners[i].sensors.load_cell_noise_kN, 0.03);
    const auto rec = record_corner(sc, i);
    const auto r = run_recording(robust, rec);
    const auto p = run_recording(paper, rec);
    std::printf("%s: robust max %.3f kN rms %.3f kN (warm-up %.2f s, %llu fits) | paper max %.3f kN rms %.3f kN\n",
                sc.corners[i].name.c_str(), r.score.max_abs_error_kN, r.score.rms_error_kN, r.score.warmup_s,
                static_cast<unsigned long long>(r.stats.fits_accepted), p.score.max_abs_error_kN, p.score.rms_error_kN);
    EXPECT_GT(r.score.samples_scored, 25000u) << sc.corners[i].name;
    EXPECT_LE(r.score.max_abs_error_kN, 0.20) << sc.corners[i].name;  // our target; the paper's is 0.27
    EXPECT_EQ(r.stats.fits_rejected, 0u) << sc.corners[i].name;
    worst_robust = std::max(worst_robust, r.score.max_abs_error_kN);
  }
  RecordProperty("worst_robust_kN", std::to_string(worst_robust));
}

TEST(CalibratorAccuracy, WrongInitialCurveConvergesWithinStatedCycles) {
  // The 28 C curve used at 54 C. Error over the PF points (the calibrated cubic at X_k against
  // the plant's true curve) must fall below 1 % of full scale (0.4 kN) within 10 cycles
  // (measured: 9; the sweep's first cycles are small and only correct part of the range).
  const auto& sc = sweep();
  const std::size_t i54 = sc.corners.size() - 1;
  ASSERT_DOUBLE_EQ(sc.corners[i54].conditions.temperature_C, 54.0);
  const bbw::plant::ClampCurve truth(sc.plant.curve);
  auto cfg = load_config(source_path("config/calibrator/robust.yaml"));
  cfg.initial_curve = test::cubic_of_true_curve(truth, 28.0, cfg.x_min_rev, cfg.x_max_rev);
  const auto rec = record_corner(sc, i54);
  Calibrator cal(cfg);
  auto pf_error = [&] {
    double e = 0.0;
    for (double X : cal.pf_positions_rev()) e = std::max(e, std::fabs(cal.curve().force_kN(X) - truth.force_kN(X, 54.0, 0.0)));
    return e;
  };
  const double initial = pf_error();
  EXPECT_GT(initial, 2.0);  // the starting curve really is wrong (over 5 % of full scale)
  int cycles_to_converge = -1;
  for (std::size_t k = 0; k < rec.time_s.size(); ++k) {
    const auto e = cal.update({rec.time_s[k], rec.position_rev[k], rec.force_kN[k]});
    if (e.fit_accepted && cycles_to_converge < 0 && pf_error() < 0.01 * cfg.full_scale_kN) {
      cycles_to_converge = static_cast<int>(cal.stats().cycles_detected) - 1;
    }
  }
  std::printf("initial PF error %.3f kN; below 0.4 kN after %d cycles; final PF error %.3f kN\n", initial,
              cycles_to_converge, pf_error());
  ASSERT_GT(cycles_to_converge, 0);
  EXPECT_LE(cycles_to_converge, 10);
  EXPECT_LT(pf_error(), 0.01 * cfg.full_scale_kN);
}

TEST(CalibratorAccuracy, OfflineAndPerSampleGiveIdenticalNumbers) {
  const auto cfg = load_config(source_path("config/calibrator/robust.yaml"));
  const auto rec = record_corner(sweep(), 8);
  const auto offline = run_recording(cfg, rec);
  Calibrator cal(cfg);
  for (std::size_t k = 0; k < rec.time_s.size(); ++k) {
    const auto e = cal.update({rec.time_s[k], rec.position_rev[k], rec.force_kN[k]});
    ASSERT_EQ(e.force_kN, offline.estimates[k].force_kN) << k;  // bit-identical
  }
}

TEST(CalibratorAccuracy, ViscousTermFoundOfflineLowersOnlineErrorWhenSwitchedOn) {
  // The plant's viscous key friction (0.2 kN per rev/s, an effect eq. 5 lacks) is on; ./bbw
  // analyze names it first (tests/analysis). Switching on the calibrator's optional viscous
  // term must at least halve the online worst-case error and recover the coefficient.
  auto sc = bbw::scenario::load_scenario(source_path("config/scenarios/paper_rig_44C.yaml"));
  sc.corners[0].effects.viscous_friction.enabled = true;
  sc.corners[0].effects.viscous_friction.coefficient_kN_per_rev_per_s = 0.2;
  const auto rec = record_corner(sc, 0);
  auto off = load_config(source_path("config/calibrator/robust.yaml"));
  auto on = off;
  on.viscous_friction = true;
  const auto before = run_recording(off, rec);
  const auto after = run_recording(on, rec);
  auto no_speed = rec;
  no_speed.speed_rev_per_s.clear();  // the position-slope fallback instead of the resolver speed
  const auto after_slope = run_recording(on, no_speed);
  std::printf("viscous on: max %.3f -> %.3f kN (slope fallback %.3f), rms %.3f -> %.3f kN, c_v %.4f kN/(rev/s)\n",
              before.score.max_abs_error_kN, after.score.max_abs_error_kN, after_slope.score.max_abs_error_kN,
              before.score.rms_error_kN, after.score.rms_error_kN, after.friction.viscous_kN_per_rev_per_s);
  EXPECT_LT(after.score.max_abs_error_kN, 0.5 * before.score.max_abs_error_kN);
  EXPECT_LT(after.score.max_abs_error_kN, 0.27);
  EXPECT_LT(after_slope.score.max_abs_error_kN, 0.5 * before.score.max_abs_error_kN);
  EXPECT_NEAR(after.friction.viscous_kN_per_rev_per_s, 0.2, 0.03);
  // Without the effect the term stays near zero and costs nothing.
  const auto clean = record_corner(bbw::scenario::load_scenario(source_path("config/scenarios/paper_rig_44C.yaml")), 0);
  const auto clean_on = run_recording(on, clean);
  const auto clean_off = run_recording(off, clean);
  EXPECT_LT(clean_on.friction.viscous_kN_per_rev_per_s, 0.03);  // measured 0.019: some model mismatch leaks in
  // Issue 13: with residual averaging clean_off fell to 0.090 kN and the term's leak (c_v 0.019)
  // now shows as 0.031 kN (0.121 vs 0.090); before, 0.03 held against a noisier baseline.
  EXPECT_LT(clean_on.score.max_abs_error_kN, clean_off.score.max_abs_error_kN + 0.04);
  EXPECT_LT(clean_on.score.max_abs_error_kN, 0.27);
}

TEST(CalibratorAccuracy, ForceDelayFoundOfflineLowersOnlineErrorWhenSwitchedOn) {
  // The plant's load cell lags the resolver by 5 ms (an effect eq. 5 lacks); ./bbw analyze
  // names it and measures 5 ms (tests/analysis). With force_delay_s set to what it measured the
  // online calibrator pairs each reading with the position 5 ms before and carries the estimate
  // to the present along the curve: the worst case must at least halve.
  auto sc = bbw::scenario::load_scenario(source_path("config/scenarios/paper_rig_44C.yaml"));
  sc.corners[0].effects.sensor_delay.enabled = true;
  sc.corners[0].effects.sensor_delay.delay_s = 0.005;
  const auto rec = record_corner(sc, 0);
  auto off = load_config(source_path("config/calibrator/robust.yaml"));
  auto on = off;
  on.force_delay_s = 0.005;
  const auto before = run_recording(off, rec);
  const auto after = run_recording(on, rec);
  auto wrong = off;
  wrong.force_delay_s = 0.010;  // twice the real delay: better than none, worse than right
  const auto after_wrong = run_recording(wrong, rec);
  std::printf("force delay 5 ms: max %.3f -> %.3f kN (10 ms assumed: %.3f), rms %.3f -> %.3f kN\n",
              before.score.max_abs_error_kN, after.score.max_abs_error_kN, after_wrong.score.max_abs_error_kN,
              before.score.rms_error_kN, after.score.rms_error_kN);
  EXPECT_LT(after.score.max_abs_error_kN, 0.5 * before.score.max_abs_error_kN);
  EXPECT_LT(after.score.max_abs_error_kN, 0.27);
  EXPECT_LT(after.score.max_abs_error_kN, after_wrong.score.max_abs_error_kN);
  // Without the effect the term is off by default and, set to 0, changes nothing bit for bit.
  const auto clean = record_corner(bbw::scenario::load_scenario(source_path("config/scenarios/paper_rig_44C.yaml")), 0);
  auto zero = off;
  zero.force_delay_s = 0.0;
  EXPECT_EQ(run_recording(zero, clean).score.max_abs_error_kN, run_recording(off, clean).score.max_abs_error_kN);
}

TEST(EstimateFusion, TrustsTheCurveOnlyAsFarAsItAgreesWithTheCompensatedLoadCell) {
  // Four-corner rig at 54 C starting from the 40 C curve: early on the curve is off by kN, so a
  // fixed 50/50 blend is worse than f_hat; the learned weighting is never worse than f_hat by
  // more than a little and is better than the fixed blend.
  const auto sc = bbw::scenario::load_scenario(source_path("config/scenarios/paper_rig_sweep.yaml"));
  const auto cfg = load_config(source_path("config/calibrator/robust.yaml"));
  const auto rec = record_corner(sc, sc.corners.size() - 1);
  Calibrator cal(cfg);
  EstimateFusion fusion(FusionParams{});
  double max_fhat = 0.0, max_fused = 0.0, max_blend = 0.0, sse_fhat = 0.0, sse_fused = 0.0;
  for (std::size_t k = 0; k < rec.time_s.size(); ++k) {
    const auto e = cal.update({rec.time_s[k], rec.position_rev[k], rec.force_kN[k]});
    const double fused = fusion.update(e, 0.001);
    if (!e.calibrated) continue;
    const double t = rec.truth_kN[k];
    max_fhat = std::max(max_fhat, std::fabs(e.force_kN - t));
    max_fused = std::max(max_fused, std::fabs(fused - t));
    max_blend = std::max(max_blend, std::fabs(0.5 * (e.force_kN + e.curve_force_kN) - t));
    sse_fhat += (e.force_kN - t) * (e.force_kN - t);
    sse_fused += (fused - t) * (fused - t);
  }
  std::printf("max error: f_hat %.3f, fused %.3f, fixed 50/50 %.3f kN; final curve weight %.3f, curve rms %.3f kN\n",
              max_fhat, max_fused, max_blend, fusion.curve_weight(), fusion.curve_rms_error_kN());
  EXPECT_LT(max_fused, max_fhat + 0.03);
  EXPECT_LT(max_fused, 0.5 * max_blend);
  EXPECT_LE(sse_fused, sse_fhat * 1.02);
  EXPECT_GT(fusion.curve_weight(), 0.0);
  EXPECT_LT(fusion.curve_weight(), 0.5);
}

TEST(EstimateFusion, PassesThroughBeforeCalibrationAndRejectsBadParams) {
  EstimateFusion f(FusionParams{});
  Estimate e;
  e.valid = true;
  e.calibrated = false;
  e.force_kN = 3.0;
  e.curve_force_kN = 10.0;
  EXPECT_DOUBLE_EQ(f.update(e, 0.001), 3.0);
  e.calibrated = true;
  // A curve whose own error is as large as the load cell's (disagreement variance 2 sigma^2)
  // gets half the weight.
  for (int k = 0; k < 20000; ++k) {
    e.curve_force_kN = e.force_kN + ((k % 2) ? 0.03 : -0.03) * std::sqrt(2.0);
    f.update(e, 0.001);
  }
  EXPECT_NEAR(f.curve_weight(), 0.5, 0.1);
  FusionParams bad;
  bad.load_cell_noise_kN = 0.0;
  EXPECT_THROW(EstimateFusion{bad}, std::invalid_argument);
}

// The same sweep with other noise seeds: the worst case over the 14 temperatures must stay
// within the paper's 0.27 kN on every one (our 0.2 kN target is a figure we report, not a
// guarantee: the load-cell noise alone reaches about 0.15 kN over 400 000 samples).
class CalibratorSeeds : public ::testing::TestWithParam<int> {};

TEST_P(CalibratorSeeds, WorstCaseWithinThePapersFigure) {
  auto sc = bbw::scenario::load_scenario(source_path("config/scenarios/paper_rig_sweep.yaml"));
  sc.seed = static_cast<std::uint64_t>(GetParam());
  const auto cfg = load_config(source_path("config/calibrator/robust.yaml"));
  double worst = 0.0;
  for (std::size_t i = 0; i < sc.corners.size(); ++i) {
    const auto r = run_recording(cfg, record_corner(sc, i));
    worst = std::max(worst, r.score.max_abs_error_kN);
  }
  std::printf("seed %d: worst max |error| over 14 temperatures %.3f kN\n", GetParam(), worst);
  EXPECT_LE(worst, 0.27);
}

INSTANTIATE_TEST_SUITE_P(NoiseSeeds, CalibratorSeeds, ::testing::Values(1, 2, 3, 4, 5));
