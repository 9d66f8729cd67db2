// The one fault scorer (bbw/faults/outcome.hpp), used by bbw_launch and the closed loop.
#include <gtest/gtest.h>

#include "bbw/faults/outcome.hpp"

namespace bbw::faults {
namespace {

FaultSpec fault(Target t, Part p, FaultType type, double at_s) {
  FaultSpec f;
  f.target = t;
  f.part = p;
  f.type = type;
  f.at_s = at_s;
  return f;
}

TEST(FaultScorer, PrefersTheInjectedPartAndTimesTheFirstDetection) {
  const FaultSpec f = fault(Target::FR, Part::LoadCell, FaultType::Bias, 2.0);
  const std::vector<DetectionEvent> d{
      {Target::FR, Finding::ResolverOffset, 1.0, 1.5},     // before the injection: ignored
      {Target::FL, Finding::LoadCellOffset, 2.0, 2.01},    // another corner: ignored
      {Target::FR, Finding::ActuatorTracking, 2.0, 2.02},  // first on the corner, wrong part
      {Target::FR, Finding::LoadCellOffset, 2.0, 2.05}};   // the right part, later
  const FaultOutcome o = score_fault(f, d);
  EXPECT_TRUE(o.detected);
  EXPECT_DOUBLE_EQ(o.detected_s, 2.02);
  EXPECT_NEAR(o.latency_ms, 20.0, 1e-9);
  EXPECT_DOUBLE_EQ(o.diagnosis_s, 2.05);
  EXPECT_NEAR(o.diagnosis_latency_ms, 50.0, 1e-9);
  EXPECT_EQ(o.diagnosis, Finding::LoadCellOffset);
  EXPECT_TRUE(o.correct);
  EXPECT_EQ(diagnosis_name(o), "load_cell_offset");
  EXPECT_STREQ(o.reaction, reaction_to(Finding::LoadCellOffset));
}

TEST(FaultScorer, AWrongPartIsDetectedButNotCorrectAndAnUpgradeRefinesTheDiagnosis) {
  const FaultSpec f = fault(Target::RL, Part::LoadCell, FaultType::Stuck, 1.0);
  const FaultOutcome o = score_fault(f, {{Target::RL, Finding::ActuatorLost, 1.0, 1.2},
                                         {Target::RL, Finding::ActuatorNotReleasing, 1.0, 1.6}});
  EXPECT_TRUE(o.detected);
  EXPECT_FALSE(o.correct);
  EXPECT_EQ(o.diagnosis, Finding::ActuatorNotReleasing);
  EXPECT_DOUBLE_EQ(o.diagnosis_s, 1.2);
}

TEST(FaultScorer, NothingDetectedAndProcessKills) {
  EXPECT_FALSE(score_fault(fault(Target::FL, Part::Resolver, FaultType::Offset, 1.0), {}).detected);
  EXPECT_EQ(diagnosis_name(score_fault(fault(Target::FL, Part::Resolver, FaultType::Offset, 1.0), {})), "none");
  // A kill names the process; a lost link is a detection, not the right diagnosis.
  const FaultSpec kill = fault(Target::RR, Part::LoadCell, FaultType::Kill, 3.0);
  EXPECT_FALSE(score_fault(kill, {{Target::RR, Finding::LinkLost, 3.0, 3.1}}).correct);
  EXPECT_TRUE(score_fault(kill, {{Target::RR, Finding::LinkLost, 3.0, 3.1}, {Target::RR, Finding::ProcessLost, 3.0, 3.5}}).correct);
}

TEST(FaultScorer, ACcuKillIsScoredByTheCornersWatchdogs) {
  const FaultSpec f = fault(Target::CCU, Part::Process, FaultType::Kill, 5.0);
  const FaultOutcome all = score_ccu_kill(f, {5.2, 5.1, 5.3, 5.2});
  EXPECT_TRUE(all.detected && all.correct);
  EXPECT_DOUBLE_EQ(all.detected_s, 5.1);
  EXPECT_EQ(diagnosis_name(all), "ccu_lost");
  const FaultOutcome some = score_ccu_kill(f, {5.2, -1.0, 5.3, 5.2});
  EXPECT_TRUE(some.detected);
  EXPECT_FALSE(some.correct);
  EXPECT_FALSE(score_ccu_kill(f, {-1.0, -1.0}).detected);
}

TEST(FaultScorer, FindingNamesRoundTrip) {
  for (Finding f : {Finding::LoadCellOffset, Finding::ResolverStuck, Finding::ActuatorNotReleasing, Finding::ProcessLost}) {
    EXPECT_EQ(finding_from_name(to_string(f)), f);
  }
  EXPECT_EQ(finding_from_name("bogus"), Finding::None);
}

}  // namespace
}  // namespace bbw::faults
