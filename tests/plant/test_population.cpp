// Caliper population: seeded, reproducible, inside its ranges, and varied where it should be.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "bbw/common/strict_yaml.hpp"
#include "bbw/plant/key_friction.hpp"
#include "bbw/plant/plant.hpp"
#include "bbw/plant/population.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/scenario/population.hpp"

using namespace bbw::plant;

namespace {

const std::string kSpecDir = BBW_SOURCE_DIR "/config/population/";

TEST(Population, SameSeedAndIndexSameCaliper) {
  const PopulationRanges r;
  const Caliper a = draw_caliper(PlantParams{}, r, 42, 3);
  const Caliper b = draw_caliper(PlantParams{}, r, 42, 3);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.params.key_friction.elements, b.params.key_friction.elements);
  EXPECT_EQ(a.params.key_friction.structure_seed, b.params.key_friction.structure_seed);
  EXPECT_DOUBLE_EQ(a.params.curve.contact_rev, b.params.curve.contact_rev);
  EXPECT_EQ(KeyFriction(a.params.key_friction).thresholds_rev(), KeyFriction(b.params.key_friction).thresholds_rev());
  const Caliper c = draw_caliper(PlantParams{}, r, 43, 3);
  EXPECT_NE(a.seed, c.seed);
  EXPECT_NE(a.params.curve.contact_rev, c.params.curve.contact_rev);
}

TEST(Population, MembersStayInsideTheirRangesAndVary) {
  const PopulationRanges r;
  std::set<int> elements;
  int log_uniform = 0;
  double hw_lo = 1e9, hw_hi = 0.0, n0_lo = 1.0, n0_hi = -1.0, t_lo = 1.0, t_hi = 0.0;
  for (int i = 0; i < 200; ++i) {
    const Caliper c = draw_caliper(PlantParams{}, r, 7, i);
    const auto& k = c.params.key_friction;
    ASSERT_GE(k.elements, 10);
    ASSERT_LE(k.elements, 60);
    elements.insert(k.elements);
    const KeyFriction f(k);
    const auto& d = f.thresholds_rev();
    ASSERT_GE(d.front(), r.threshold_min_rev.min * (1 - 1e-12));
    ASSERT_LE(d.back(), r.threshold_max_limit_rev * (1 + 1e-12));
    t_lo = std::min(t_lo, d.front());
    t_hi = std::max(t_hi, d.back());
    ASSERT_NEAR(f.half_width_kN(), k.half_width_kN, 1e-9);
    hw_lo = std::min(hw_lo, k.half_width_kN);
    hw_hi = std::max(hw_hi, k.half_width_kN);
    n0_lo = std::min(n0_lo, k.initial_deflection);
    n0_hi = std::max(n0_hi, k.initial_deflection);
    log_uniform += k.threshold_distribution == ThresholdDistribution::LogUniform ? 1 : 0;
    ASSERT_GE(c.params.curve.contact_rev, 0.2);
    ASSERT_LE(c.params.curve.contact_rev, 1.0);
    ASSERT_GE(c.stiffness_scale, 0.7);
    ASSERT_LE(c.stiffness_scale, 1.3);
    ASSERT_GE(c.params.sensors.load_cell_noise_kN, 0.02);
    ASSERT_LE(c.params.sensors.load_cell_noise_kN, 0.05);
  }
  EXPECT_GT(elements.size(), 30u);
  EXPECT_GT(log_uniform, 60);
  EXPECT_LT(log_uniform, 140);
  EXPECT_LT(hw_lo, 0.6);
  EXPECT_GT(hw_hi, 1.9);
  EXPECT_LT(n0_lo, -0.9);
  EXPECT_GT(n0_hi, 0.9);
  EXPECT_LT(t_lo, 0.003);   // narrow and wide frictions both drawn
  EXPECT_GT(t_hi, 0.7);
}

TEST(Population, UnevenSharesChangeTheStiffnesses) {
  KeyFrictionParams smooth;
  KeyFrictionParams uneven = smooth;
  uneven.share_log_sigma = 1.0;
  const KeyFriction a(smooth), b(uneven);
  EXPECT_EQ(a.thresholds_rev(), b.thresholds_rev());
  EXPECT_NEAR(b.half_width_kN(), smooth.half_width_kN, 1e-9);
  double diff = 0.0;
  for (std::size_t i = 0; i < a.elements(); ++i) {
    diff = std::max(diff, std::fabs(std::log(a.stiffness_kN_per_rev()[i] / b.stiffness_kN_per_rev()[i])));
  }
  EXPECT_GT(diff, 0.5);
}

TEST(Population, InitialDeflectionStartsTheFrictionSaturated) {
  KeyFrictionParams k;
  k.initial_deflection = 1.0;
  KeyFriction f(k);
  f.reset(2.0);
  EXPECT_NEAR(f.force_kN(), k.half_width_kN, 1e-9);
  // Holding still keeps it; moving up keeps it saturated; a full reversal flips it.
  EXPECT_NEAR(f.step(2.0), k.half_width_kN, 1e-9);
  EXPECT_NEAR(f.step(3.0), k.half_width_kN, 1e-9);
  EXPECT_NEAR(f.step(0.0), -k.half_width_kN, 1e-9);
  // The plant reports it from its first sample.
  PlantParams p;
  p.key_friction = k;
  p.sensors.load_cell_noise_kN = 0.0;
  Plant plant(p, EffectsParams{}, Conditions{}, 1);
  plant.reset(2.0);
  EXPECT_NEAR(plant.state().key_friction_kN, k.half_width_kN, 1e-9);
  EXPECT_NEAR(plant.measurement().force_internal_kN - plant.state().force_true_kN, k.half_width_kN, 1e-9);
}

TEST(Population, RangesValidateNamesTheField) {
  PopulationRanges r;
  r.contact_rev = {1.0, 0.5};
  try {
    r.validate();
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("contact_rev"), std::string::npos) << e.what();
  }
}

TEST(PopulationSpec, ShippedSpecsLoadWithDifferentSeeds) {
  const auto tuning = bbw::scenario::load_population_spec(kSpecDir + "tuning.yaml");
  const auto scoring = bbw::scenario::load_population_spec(kSpecDir + "scoring.yaml");
  EXPECT_NE(tuning.seed, scoring.seed);
  EXPECT_GE(scoring.count, 30);
  EXPECT_EQ(scoring.temperatures_C, (std::vector<double>{28.0, 40.0, 54.0}));
  const auto sc = bbw::scenario::population_scenario(scoring, 4);
  ASSERT_EQ(sc.corners.size(), 3u);
  EXPECT_EQ(sc.corners[0].name, "T28");
  EXPECT_EQ(sc.corners[2].conditions.temperature_C, 54.0);
  EXPECT_EQ(sc.plant.key_friction.structure_seed,
            bbw::scenario::population_member(scoring, 4).params.key_friction.structure_seed);
  EXPECT_THROW(bbw::scenario::population_member(scoring, scoring.count), std::out_of_range);
}

std::string spec_text(const std::string& extra_range) {
  return "name: t\nseed: 1\ncount: 2\ntemperatures_C: [40]\nduration_s: 1\nplant_dt_s: 0.001\n"
         "plant: " + std::string(BBW_SOURCE_DIR) + "/config/plant/ecaliper.yaml\n"
         "drive: {mode: position, segments: [{type: hold, position_rev: 1.0, duration_s: 1.0}]}\n"
         "ranges:\n  elements: [10, 60]\n  threshold_min_rev: [0.002, 0.05]\n  threshold_span_ratio: [3, 400]\n"
         "  threshold_max_limit_rev: 0.8\n  log_uniform_share: 0.5\n  half_width_kN: [0.5, 2]\n"
         "  force_share_exponent: [-0.5, 1]\n  share_log_sigma: [0, 1]\n  initial_deflection: [-1, 1]\n"
         "  contact_rev: [0.2, 1.0]\n  stiffness_scale: [0.7, 1.3]\n  contact_shift_rev_per_C: [0.002, 0.006]\n"
         "  stiffness_change_per_C: [-0.006, -0.002]\n" + extra_range;
}

TEST(PopulationSpec, StrictLoaderNamesFileLineAndKey) {
  // Missing key.
  try {
    bbw::scenario::load_population_spec_string(spec_text(""), "spec.yaml");
    FAIL() << "missing load_cell_noise_kN accepted";
  } catch (const bbw::config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("ranges.load_cell_noise_kN"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("spec.yaml"), std::string::npos) << e.what();
  }
  const std::string ok = "  load_cell_noise_kN: [0.02, 0.05]\n";
  EXPECT_NO_THROW(bbw::scenario::load_population_spec_string(spec_text(ok), "spec.yaml"));
  // Unknown key, with its line.
  try {
    bbw::scenario::load_population_spec_string(spec_text(ok + "  friction_colour: [1, 2]\n"), "spec.yaml");
    FAIL() << "unknown key accepted";
  } catch (const bbw::config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("ranges.friction_colour"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(":24"), std::string::npos) << e.what();
  }
  // Reversed interval.
  EXPECT_THROW(bbw::scenario::load_population_spec_string(spec_text("  load_cell_noise_kN: [0.05, 0.02]\n"), "s"),
               bbw::config::ConfigError);
}

TEST(PopulationSpec, ScenarioKeyPicksAMember) {
  const std::string text = "name: pick\nseed: 3\nduration_s: 1\nplant: " + std::string(BBW_SOURCE_DIR) +
                           "/config/plant/ecaliper.yaml\npopulation: {spec: " + kSpecDir +
                           "scoring.yaml, member: 5}\ncorners:\n  - name: T40\n    temperature_C: 40\n"
                           "    drive: {mode: position, segments: [{type: hold, position_rev: 1.0, duration_s: 1.0}]}\n";
  const auto sc = bbw::scenario::load_scenario_string(text, "pick.yaml");
  const auto spec = bbw::scenario::load_population_spec(kSpecDir + "scoring.yaml");
  const auto member = bbw::scenario::population_member(spec, 5);
  EXPECT_EQ(sc.plant.key_friction.structure_seed, member.params.key_friction.structure_seed);
  EXPECT_DOUBLE_EQ(sc.corners[0].sensors.load_cell_noise_kN, member.params.sensors.load_cell_noise_kN);
  auto out_of_range = text;
  out_of_range.replace(out_of_range.find("member: 5"), 9, "member: 99");
  EXPECT_THROW(bbw::scenario::load_scenario_string(out_of_range, "pick.yaml"), bbw::config::ConfigError);
}

}  // namespace
