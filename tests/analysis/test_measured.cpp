// Issue 6 on measured data (../shared/datasets or $BBW_DATASETS): the findings written in
// docs/measured-data.md, pinned so that a change that loses them fails.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "bbw/analysis/analysis.hpp"
#include "bbw/analyze/cli.hpp"

using namespace bbw;

namespace {

std::string dataset(const std::string& rel) {
  namespace fs = std::filesystem;
  std::vector<std::string> roots;
  if (const char* d = std::getenv("BBW_DATASETS")) roots.push_back(d);
  const char* src = std::getenv("BBW_SOURCE_DIR");
  roots.push_back(std::string(src ? src : ".") + "/../shared/datasets");
  for (const auto& r : roots)
    if (fs::exists(fs::path(r) / rel)) return (fs::path(r) / rel).string();
  return "";
}

const analysis::Parameter* param(const std::vector<analysis::Parameter>& ps, const std::string& name) {
  for (const auto& p : ps)
    if (p.name == name) return &p;
  return nullptr;
}

std::vector<std::string> step_names(const analysis::AnalysisResult& r) {
  std::vector<std::string> n;
  for (const auto& s : r.steps) n.push_back(s.evidence.name);
  return n;
}

}  // namespace

// EMPS: force from position only (the controller voltage vir_V is the force divided by gtau and
// the reference qg_m is the controller's input, so neither is offered as a channel). The benchmark's
// inverse model: mass 95.1 kg, viscous 203.5 N s/m, Coulomb 20.4 N.
TEST(MeasuredEmps, InertiaAndViscousFoundNearTheReferenceModel) {
  const std::string f = dataset("emps/emps_estimation.csv");
  if (f.empty()) GTEST_SKIP() << "EMPS data set not found (set BBW_DATASETS or place ../shared/datasets)";
  const auto in = analyze::load_recording(
      analyze::parse_args({"--input", f, "--position", "qm_m", "--force", "force_N", "--channels", "none", "--out", "unused"}));
  const auto r = analysis::analyze(in.rec, analysis::AnalysisOptions{});
  const auto n = step_names(r);
  ASSERT_GE(n.size(), 2u);
  EXPECT_EQ(n[0], "inertia");
  EXPECT_EQ(n[1], "viscous_friction");
  const auto* m = param(r.final_parameters, "inertia.mass");
  const auto* v = param(r.final_parameters, "viscous_friction.coefficient");
  const auto* c = param(r.final_parameters, "friction_bound");
  ASSERT_TRUE(m && v && c);
  EXPECT_NEAR(m->value, 95.1, 0.05 * 95.1);    // within 5 %
  EXPECT_NEAR(v->value, 203.5, 0.05 * 203.5);  // within 5 %
  EXPECT_NEAR(c->value, 20.4, 0.1 * 20.4);     // Maxwell-slip bound vs Coulomb, within 10 %
  EXPECT_LT(r.final_errors.rms_residual, 0.1 * r.baseline.rms_residual);
}

// MR damper: the coil voltage times velocity is the first effect (the damper's viscous part is
// switched by the coil); the recorded velocity channel adds nothing beyond the derived velocity.
TEST(MeasuredMrDamper, CoilVoltageTimesVelocityFoundFirst) {
  const std::string f = dataset("mr-damper-dyke/ranran_50.csv");
  if (f.empty()) GTEST_SKIP() << "MR damper data set not found (set BBW_DATASETS or place ../shared/datasets)";
  const auto in = analyze::load_recording(analyze::parse_args(
      {"--input", f, "--time", "t_s", "--position", "D_cm", "--force", "F_N", "--channels", "V_cm_s,Y_V", "--out", "unused"}));
  const auto r = analysis::analyze(in.rec, analysis::AnalysisOptions{});
  const auto n = step_names(r);
  ASSERT_FALSE(n.empty());
  EXPECT_EQ(n[0], "channel:Y_V*velocity");
  EXPECT_GT(r.steps[0].parameters.at(0).value, 0.0);  // more damping with coil voltage
  EXPECT_LT(r.final_errors.holdout_rms_residual, 0.8 * r.baseline.holdout_rms_residual);
  EXPECT_TRUE(r.unexplained_structure);  // the damper's hysteresis is more than eq. 5 + candidates
}
