// Issue 13: the shipped robust config on the scoring population (config/population/scoring.yaml),
// calipers it was not tuned on (settings were chosen on config/population/tuning.yaml, another
// seed). Every member x temperature must meet the paper's 0.27 kN after the first accepted fit and
// an RMS of 0.04 kN.
// The same figures: ./bbw ablation --population config/population/scoring.yaml --distribution
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/plant/population.hpp"
#include "bbw/scenario/population.hpp"
#include "rig_recording.hpp"

using namespace bbw::calibration;
using bbw::calibration::test::source_path;

TEST(CalibratorPopulation, ScoringPopulationEveryRecordingWithinPaperBound) {
  const auto robust = load_config(source_path("config/calibrator/robust.yaml"));
  const auto spec = bbw::scenario::load_population_spec(source_path("config/population/scoring.yaml"));
  const auto tuning = bbw::scenario::load_population_spec(source_path("config/population/tuning.yaml"));
  ASSERT_NE(spec.seed, tuning.seed) << "scored on the population the settings were tuned on";
  ASSERT_GE(spec.count, 30);
  ASSERT_EQ(spec.temperatures_C.size(), 3u);
  std::vector<double> worst;
  double rms_sum = 0.0;
  std::string worst_name;
  double worst_kN = 0.0;
  for (int m = 0; m < spec.count; ++m) {
    const auto sc = bbw::scenario::population_scenario(spec, m);
    for (std::size_t i = 0; i < sc.corners.size(); ++i) {
      const auto rec = record_corner(sc, i);
      const auto r = run_recording(robust, rec);
      std::string name = "c";
      name += std::to_string(m);
      name += "_";
      name += sc.corners[i].name;
      name += " (";
      name += bbw::plant::describe_key_friction(sc.plant.key_friction);
      name += ")";
      ASSERT_GT(r.stats.fits_accepted, 0u) << name;
      EXPECT_GT(r.score.samples_scored, 20000u) << name;
      EXPECT_LE(r.score.max_abs_error_kN, 0.27) << name << " at " << r.score.time_of_max_error_s << " s";
      EXPECT_LE(r.score.rms_error_kN, 0.04) << name;  // issue 13: RMS per recording
      worst.push_back(r.score.max_abs_error_kN);
      rms_sum += r.score.rms_error_kN;
      if (r.score.max_abs_error_kN > worst_kN) {
        worst_kN = r.score.max_abs_error_kN;
        worst_name = name;
      }
    }
  }
  std::sort(worst.begin(), worst.end());
  std::printf("scoring population, %zu recordings: worst |f_hat - f_ext| median %.3f, p90 %.3f, worst %.3f kN (%s); "
              "mean RMS %.4f kN\n",
              worst.size(), worst[worst.size() / 2], worst[worst.size() * 9 / 10], worst_kN, worst_name.c_str(),
              rms_sum / static_cast<double>(worst.size()));
  EXPECT_LE(rms_sum / static_cast<double>(worst.size()), 0.04);  // mean RMS over the recordings
  RecordProperty("worst_kN", std::to_string(worst_kN));
}

// Issue 13's friction memory (docs/calibrator.md, robust item 9), on the tuning-population
// recording the change was traced on (c7_T54: its first cycles gave 0.10 kN to 0.53 and 0.8 rev
// elements the caliper does not have, carried afterwards through the local loops): without the
// memory its RMS is above 0.04 kN, with the shipped 0.9 below, and the worst error is no larger.
TEST(CalibratorPopulation, FrictionMemoryKeepsWhatTheWideCyclesSaid) {
  auto with = load_config(source_path("config/calibrator/robust.yaml"));
  ASSERT_GT(with.friction_memory, 0.0);
  auto without = with;
  without.friction_memory = 0.0;
  const auto spec = bbw::scenario::load_population_spec(source_path("config/population/tuning.yaml"));
  const auto sc = bbw::scenario::population_scenario(spec, 7);
  ASSERT_EQ(sc.corners.size(), 3u);
  const auto rec = record_corner(sc, 2);  // 54 C
  const auto a = run_recording(without, rec);
  const auto b = run_recording(with, rec);
  ASSERT_GT(a.stats.fits_accepted, 0u);
  ASSERT_GT(b.stats.fits_accepted, 0u);
  EXPECT_GT(a.score.rms_error_kN, 0.04);
  EXPECT_LE(b.score.rms_error_kN, 0.04);
  EXPECT_LE(b.score.max_abs_error_kN, a.score.max_abs_error_kN);
}
