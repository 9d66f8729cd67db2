#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "bbw/analysis/options.hpp"
#include "bbw/analyze/config_loader.hpp"

using namespace bbw;

namespace {
std::string source_dir() {
  const char* s = std::getenv("BBW_SOURCE_DIR");
  return s ? s : ".";
}
}  // namespace

TEST(AnalysisOptions, DefaultsAreValid) { EXPECT_NO_THROW(analysis::AnalysisOptions{}.validate()); }

TEST(AnalysisOptions, ValidateNamesFieldAndRule) {
  analysis::AnalysisOptions o;
  o.holdout_fraction = 0.9;
  try {
    o.validate();
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("holdout_fraction = 0.9"), std::string::npos) << e.what();
  }
  o = {};
  o.sensor_effects = {"gremlins"};
  EXPECT_THROW(o.validate(), std::invalid_argument);
  o = {};
  o.curve_knots_grid = {0, 3, 2};
  EXPECT_THROW(o.validate(), std::invalid_argument);
}

TEST(AnalysisConfig, DefaultFileLoadsAndEqualsTheStructDefaults) {
  const auto o = analyze::load_options_file(source_dir() + "/config/analysis/default.yaml");
  const analysis::AnalysisOptions d;
  EXPECT_EQ(o.curve_knots_grid, d.curve_knots_grid);
  EXPECT_EQ(o.elements_M, d.elements_M);
  EXPECT_EQ(o.delta_max_fractions, d.delta_max_fractions);
  EXPECT_EQ(o.split_blocks, d.split_blocks);
  EXPECT_DOUBLE_EQ(o.velocity_window_s, d.velocity_window_s);
  EXPECT_DOUBLE_EQ(o.min_relative_drop, d.min_relative_drop);
  EXPECT_EQ(o.delay_grid_s, d.delay_grid_s);
  EXPECT_EQ(o.candidates, d.candidates);
  EXPECT_EQ(o.sensor_effects, d.sensor_effects);
}

TEST(AnalysisConfig, UnknownKeyAndBadValueAreErrorsWithLocation) {
  auto r = config::Reader::from_string("acceptance:\n  min_relative_drop: 0.05\n  typo: 1\n", "mem.yaml");
  try {
    analyze::load_options(r);
    FAIL() << "no throw";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.key_path(), "acceptance.typo");
    EXPECT_EQ(e.line(), 3);
  }
  auto r2 = config::Reader::from_string("holdout:\n  fraction: 0.8\n", "mem.yaml");
  EXPECT_THROW(analyze::load_options(r2), config::ConfigError);
  auto r3 = config::Reader::from_string("effects:\n  warp_drive: {try: true}\n", "mem.yaml");
  EXPECT_THROW(analyze::load_options(r3), config::ConfigError);
}

TEST(AnalysisConfig, EffectsMapSwitchesCandidatesAndAttribution) {
  auto r = config::Reader::from_string(
      "effects:\n  creep: {try: false}\n  backlash: {sensor: true}\n", "mem.yaml");
  const auto o = analyze::load_options(r);
  EXPECT_FALSE(o.is_candidate("creep"));
  EXPECT_TRUE(o.is_candidate("backlash"));
  EXPECT_TRUE(o.is_sensor_effect("backlash"));
  EXPECT_TRUE(o.is_sensor_effect("viscous_friction"));
}

// bbw_analyze's friction: the shipped calibrator's element set for a position in rev, the
// Delta_max grid (empty set) for another unit or --calibrator none.
TEST(AnalysisConfig, FrictionFromTheCalibratorOnlyForAPositionInRev) {
  const auto shipped = analyze::calibrator_friction_thresholds("", "rev");
  EXPECT_FALSE(shipped.empty());
  EXPECT_TRUE(analyze::calibrator_friction_thresholds("", "m").empty());
  EXPECT_TRUE(analyze::calibrator_friction_thresholds("none", "rev").empty());
  const std::string file = source_dir() + "/config/calibrator/robust.yaml";
  EXPECT_EQ(analyze::calibrator_friction_thresholds(file, "m"), shipped);
}
