// Issue 13 item 6: ./bbw analyze on a population recording whose friction starts saturated.
// The samples before the position has travelled 2 Delta_max from its running extreme are left
// out of the max figures (the online calibrator's StatesKnown rule), so the unknown initial
// state no longer dominates them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "bbw/analysis/analysis.hpp"
#include "caliper_options.hpp"
#include "bbw/calibration/calibrator.hpp"
#include "bbw/calibration/config_yaml.hpp"
#include "bbw/model/maxwell_slip.hpp"
#include "bbw/model/states_known.hpp"
#include "bbw/scenario/corner_sim.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/scenario/population.hpp"

using namespace bbw;

namespace {

std::string source_dir() {
  const char* s = std::getenv("BBW_SOURCE_DIR");
  return s ? s : BBW_SOURCE_DIR_FALLBACK;
}

analysis::Recording record(const scenario::Scenario& sc) {
  scenario::CornerSim sim(sc, 0);
  analysis::Recording r;
  const auto steps = static_cast<std::size_t>(std::llround(sc.duration_s / sc.plant_dt_s));
  for (std::size_t k = 0; k < steps; ++k) {
    const auto& s = sim.step(sc.plant_dt_s);
    r.time_s.push_back(s.time_s);
    r.position.push_back(s.position_rev);
    r.force.push_back(s.force_internal_kN);
    r.truth.push_back(s.force_external_kN);
  }
  return r;
}

}  // namespace

TEST(StatesKnown, TwoDeltaMaxFromTheRunningExtreme) {
  calibration::StatesKnown s(0.5);
  EXPECT_FALSE(s.update(2.0));
  EXPECT_FALSE(s.update(2.9));   // 0.9 up from the lowest
  EXPECT_FALSE(s.update(2.2));   // 0.7 down from the highest
  EXPECT_FALSE(s.update(1.95));  // 0.95 down; the new lowest
  EXPECT_TRUE(s.update(2.95));   // 1.0 up from 1.95
  EXPECT_TRUE(s.update(2.5));    // stays known
  const double x[] = {0.0, -0.3, 0.2, 0.8, 1.0};
  EXPECT_EQ(calibration::first_known_sample(x, 5, 0.5), 3u);  // 0.8 - (-0.3) >= 1.0 first at index 3
  EXPECT_EQ(calibration::first_known_sample(x, 5, 0.7), 5u);  // never 1.4
}

TEST(AnalyzePopulation, SaturatedInitialFrictionDoesNotDominateTheMaxFigures) {
  const auto spec = scenario::load_population_spec(source_dir() + "/config/population/scoring.yaml");
  auto sc = scenario::population_scenario(spec, 0);
  sc.corners.resize(1);  // 28 C
  sc.plant.key_friction.half_width_kN = 2.0;
  sc.plant.key_friction.initial_deflection = -1.0;  // the drive starts upwards: the worst start
  const auto saturated = analysis::analyze(record(sc), test::caliper_options());
  sc.plant.key_friction.initial_deflection = 0.0;
  const auto relaxed = analysis::analyze(record(sc), test::caliper_options());
  std::printf("unscored %zu samples; max error vs truth saturated %.3f, relaxed %.3f kN; RMS %.3f / %.3f kN\n",
              saturated.baseline.unscored_initial_samples, saturated.baseline.max_truth_error,
              relaxed.baseline.max_truth_error, saturated.baseline.rms_truth_error, relaxed.baseline.rms_truth_error);
  EXPECT_GT(saturated.baseline.unscored_initial_samples, 100u);
  // What was left out: the start, where the relaxed model meets the saturated friction.
  double start_max = 0.0;
  for (std::size_t k = 0; k < saturated.baseline.unscored_initial_samples; ++k) {
    start_max = std::max(start_max, std::abs(saturated.truth_error_before[k]));
  }
  std::printf("max error vs truth over the unscored start: %.3f kN\n", start_max);
  EXPECT_GT(start_max, 1.0);
  // The left-out start carried errors near the full friction width (2 x 2 kN at worst); the
  // scored max stays close to the relaxed recording's.
  EXPECT_LT(saturated.baseline.max_truth_error, relaxed.baseline.max_truth_error + 0.15);
  EXPECT_LT(saturated.final_errors.max_truth_error, relaxed.final_errors.max_truth_error + 0.15);
}

TEST(AnalyzeOutliers, OneGrossPositionOutlierIsRejectedAndCreatesNoEffect) {
  const auto spec = scenario::load_population_spec(source_dir() + "/config/population/scoring.yaml");
  auto sc = scenario::population_scenario(spec, 1);
  sc.corners.resize(1);
  auto rec = record(sc);
  // A recorded channel the analysis could blame for the spike, as in the file.
  rec.channels.push_back({"command", rec.position});
  const auto clean = analysis::analyze(rec, test::caliper_options());
  auto bad = rec;
  bad.position[12345] = 1e10;
  const auto r = analysis::analyze(bad, test::caliper_options());
  std::printf("clean: %zu steps, RMS residual %.4f kN; with the outlier: %zu steps, RMS residual %.4f kN, %zu outlier(s) %s\n",
              clean.steps.size(), clean.final_errors.rms_residual, r.steps.size(), r.final_errors.rms_residual,
              r.gross_outliers, r.gross_outlier_samples.empty() ? "" : r.gross_outlier_samples.front().c_str());
  EXPECT_EQ(clean.gross_outliers, 0u);
  EXPECT_EQ(r.gross_outliers, 1u);
  ASSERT_EQ(r.gross_outlier_samples.size(), 1u);
  EXPECT_EQ(r.gross_outlier_samples[0], "position@12345");
  EXPECT_EQ(r.steps.size(), clean.steps.size());
  for (std::size_t i = 0; i < std::min(r.steps.size(), clean.steps.size()); ++i) {
    EXPECT_EQ(r.steps[i].evidence.name, clean.steps[i].evidence.name);
  }
  EXPECT_NEAR(r.final_errors.rms_residual, clean.final_errors.rms_residual, 0.002);
  // The rule itself: a reading inside the bulk's range is never touched.
  analysis::Recording mild = rec;
  mild.position[100] = *std::max_element(rec.position.begin(), rec.position.end());
  EXPECT_EQ(analysis::reject_gross_outliers(mild), 0u);
}

TEST(AnalyzeBounds, UnphysicalCreepIsRejectedWithItsReason) {
  // A load cell that overshoots and relaxes upwards: the plant's creep with its sign flipped.
  // Creep would fit it best with a negative unrelaxed fraction, which no pad can have.
  const auto spec = scenario::load_population_spec(source_dir() + "/config/population/scoring.yaml");
  auto sc = scenario::population_scenario(spec, 2);
  sc.corners.resize(1);
  sc.corners[0].effects.creep.enabled = true;
  sc.corners[0].effects.creep.relaxation_fraction = 0.1;
  sc.corners[0].effects.creep.time_constant_s = 1.0;
  scenario::CornerSim sim(sc, 0);
  analysis::Recording rec;
  const auto steps = static_cast<std::size_t>(std::llround(sc.duration_s / sc.plant_dt_s));
  for (std::size_t k = 0; k < steps; ++k) {
    const auto& s = sim.step(sc.plant_dt_s);
    rec.time_s.push_back(s.time_s);
    rec.position.push_back(s.position_rev);
    rec.force.push_back(s.force_internal_kN - 2.0 * sim.plant().state().creep_kN);
  }
  const auto r = analysis::analyze(rec, test::caliper_options());
  for (const auto& st : r.steps) {
    EXPECT_NE(st.evidence.name, "creep") << "creep accepted with an unphysical fraction";
  }
  bool listed = false;
  for (const auto& c : r.rejected) {
    if (c.name == "creep") {
      listed = true;
      std::printf("creep rejected: %s (held-out drop %.1f %%)\n", c.rejected_reason.c_str(), 100.0 * c.relative_drop);
      EXPECT_NE(c.rejected_reason.find("creep.unrelaxed_fraction"), std::string::npos) << c.rejected_reason;
      EXPECT_NE(c.rejected_reason.find("must be in [0, 1)"), std::string::npos) << c.rejected_reason;
    }
  }
  EXPECT_TRUE(listed) << "creep not in `rejected`";
}

namespace {

// The paper rig at 40 C ramping 0.5 C/s with a load-cell offset drifting 0.02 kN/C; x_low is
// where each sweep cycle turns (0.3 rev: the pads open; 1.0 rev: they never do).
analysis::Recording thermal_rig(double x_low_rev) {
  auto sc = scenario::load_scenario(source_dir() + "/config/scenarios/paper_rig_44C.yaml");
  auto& k = sc.corners[0];
  k.conditions.temperature_C = 40.0;
  k.conditions.temperature_rate_C_per_s = 0.5;
  k.effects.thermal_drift.enabled = true;
  std::get<scenario::PaperSweep>(k.drive.position.segments[0]).x_low_rev = x_low_rev;
  scenario::CornerSim sim(sc, 0);
  analysis::Recording r;
  const auto steps = static_cast<std::size_t>(std::llround(sc.duration_s / sc.plant_dt_s));
  for (std::size_t i = 0; i < steps; ++i) {
    const auto& s = sim.step(sc.plant_dt_s);
    r.time_s.push_back(s.time_s);
    r.position.push_back(s.position_rev);
    r.force.push_back(s.force_internal_kN);
    r.truth.push_back(s.force_external_kN);
    r.temperature.push_back(s.temperature_C);
    r.velocity.push_back(s.speed_rev_per_s);
  }
  return r;
}

const analysis::Step* drift_step(const analysis::AnalysisResult& r) {
  for (const auto& s : r.steps)
    if (s.evidence.name == "temperature_drift") return &s;
  return nullptr;
}

}  // namespace

TEST(AnalyzeAmbiguity, OffsetVersusCurveShiftIsAmbiguousOnlyWhenThePadsNeverOpen) {
  const auto open = analysis::analyze(thermal_rig(0.3), test::caliper_options());
  const auto closed = analysis::analyze(thermal_rig(1.0), test::caliper_options());
  const auto* so = drift_step(open);
  const auto* sc = drift_step(closed);
  ASSERT_NE(so, nullptr);
  std::printf("pads open: correlation %.4f, offset SE %.5f kN/C, ambiguous %d\n", so->offset_shift_correlation,
              so->offset_standard_error, so->ambiguous ? 1 : 0);
  if (sc) {
    std::printf("pads closed: correlation %.4f, offset SE %.5f kN/C, ambiguous %d\n", sc->offset_shift_correlation,
                sc->offset_standard_error, sc->ambiguous ? 1 : 0);
  }
  EXPECT_FALSE(so->ambiguous);
  ASSERT_NE(sc, nullptr) << "with the pads closed the drift is still an effect, only its split is unknown";
  EXPECT_TRUE(sc->ambiguous);
  // An ambiguous split proposes no online load-cell offset term; a clear one does.
  bool open_term = false, closed_term = false;
  for (const auto& t : analysis::calibrator_terms(open)) open_term = open_term || t.key == "load_cell_offset_kN_per_C";
  for (const auto& t : analysis::calibrator_terms(closed)) closed_term = closed_term || t.key == "load_cell_offset_kN_per_C";
  EXPECT_TRUE(open_term);
  EXPECT_FALSE(closed_term);
}

// Issue 13 item 6: analyze's friction structure and the online calibrator's are the same
// method in one place (calibration::friction_thresholds_rev): the calibrator runs that element
// set and analyze fits it, with no Delta_max of its own.
TEST(AnalyzeFriction, FitsTheOnlineCalibratorsElementSet) {
  const auto cfg = calibration::load_config(source_dir() + "/config/calibrator/robust.yaml");
  const auto set = calibration::friction_thresholds_rev(cfg);
  ASSERT_EQ(set.size(), static_cast<std::size_t>(cfg.elements_M));
  EXPECT_EQ(calibration::Calibrator(cfg).friction().delta_rev, set);
  const auto opt = test::caliper_options();
  EXPECT_EQ(opt.friction_thresholds, set);
  const auto spec = scenario::load_population_spec(source_dir() + "/config/population/scoring.yaml");
  auto sc = scenario::population_scenario(spec, 0);
  sc.corners.resize(1);
  const auto r = analysis::analyze(record(sc), opt);
  EXPECT_EQ(r.baseline_delta_max, cfg.delta_max_rev);
  std::size_t k_params = 0;
  for (const auto& p : r.final_parameters) k_params += p.name.rfind("K_", 0) == 0 ? 1 : 0;
  EXPECT_EQ(k_params, set.size());
  for (const auto& st : r.steps) EXPECT_EQ(st.delta_max, cfg.delta_max_rev);
}
