// The analysis on small synthetic recordings (tests/analysis/synthetic.hpp): a friction model
// richer than the one fitted, one or two injected effects, white noise.
#include <gtest/gtest.h>

#include "bbw/analysis/analysis.hpp"
#include "synthetic.hpp"

using namespace bbw::analysis;

namespace {

AnalysisResult run(const std::set<std::string>& effects) {
  test::SyntheticOptions so;
  so.effects = effects;
  return analyze(test::synthetic(so), AnalysisOptions{});
}

std::vector<std::string> names(const AnalysisResult& r) {
  std::vector<std::string> n;
  for (const auto& s : r.steps) n.push_back(s.evidence.name);
  return n;
}

}  // namespace

TEST(AnalysisSynthetic, NoEffectAddsNothingAndLeavesNoStructure) {
  const auto r = run({});
  EXPECT_TRUE(r.steps.empty()) << (r.steps.empty() ? "" : r.steps[0].evidence.name);
  EXPECT_FALSE(r.unexplained_structure);
  EXPECT_NEAR(r.final_errors.rms_residual, 0.02, 0.01);  // the noise
}

TEST(AnalysisSynthetic, ViscousFrictionFoundWithItsCoefficient) {
  const auto r = run({"viscous_friction"});
  ASSERT_FALSE(r.steps.empty());
  EXPECT_EQ(r.steps[0].evidence.name, "viscous_friction");
  ASSERT_EQ(r.steps[0].parameters.size(), 1u);
  EXPECT_NEAR(r.steps[0].parameters[0].value, 0.06, 0.01);
  EXPECT_LE(r.final_errors.max_truth_error, 0.5 * r.baseline.max_truth_error);
}

TEST(AnalysisSynthetic, SensorDelayFoundWithItsDelay) {
  const auto r = run({"sensor_delay"});
  ASSERT_FALSE(r.steps.empty());
  EXPECT_EQ(r.steps[0].evidence.name, "sensor_delay");
  EXPECT_NEAR(r.steps[0].evidence.hyper_value, 0.006, 0.0015);
  EXPECT_LE(r.final_errors.max_truth_error, 0.5 * r.baseline.max_truth_error);
}

TEST(AnalysisSynthetic, CoilVoltageTimesVelocityChannelFound) {
  const auto r = run({"coil"});
  ASSERT_FALSE(r.steps.empty());
  EXPECT_EQ(r.steps[0].evidence.name, "channel:coil_V*velocity");
  EXPECT_NEAR(r.steps[0].parameters[0].value, 0.08, 0.015);
}

TEST(AnalysisSynthetic, TwoEffectsBothFound) {
  const auto r = run({"viscous_friction", "backlash"});
  const auto n = names(r);
  EXPECT_NE(std::find(n.begin(), n.end(), "viscous_friction"), n.end());
  EXPECT_NE(std::find(n.begin(), n.end(), "backlash"), n.end());
}

TEST(AnalysisSynthetic, RejectsUnusableRecordings) {
  Recording r;
  r.time_s = {0.0, 0.001};
  r.position = {0.0, 1.0};
  r.force = {0.0, 1.0};
  EXPECT_THROW(analyze(r, AnalysisOptions{}), std::invalid_argument);
  test::SyntheticOptions so;
  so.duration_s = 1.0;
  auto ok = test::synthetic(so);
  ok.force.pop_back();
  EXPECT_THROW(analyze(ok, AnalysisOptions{}), std::invalid_argument);
}
