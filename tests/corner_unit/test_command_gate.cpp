// The corner's command gate (issue 17): run id, pinned source, clamp-force range and rate.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "bbw/corner/command_gate.hpp"

namespace {

using bbw::corner::CommandGate;
using bbw::corner::CommandGateParams;
using bbw::corner::CommandSource;
using bbw::corner::GateVerdict;

constexpr std::uint64_t kRun = 0x1234abcdULL;

CommandSource from(std::uint8_t writer, std::uint64_t run = kRun, bool announced_as_ccu = true) {
  CommandSource s;
  s.run_id = run;
  s.writer.fill(writer);
  s.announced_as_ccu = announced_as_ccu;
  return s;
}

CommandGateParams params() {
  CommandGateParams p;
  p.max_force_kN = 40.0;
  p.max_rate_kN_per_s = 8000.0;  // 40 kN per 5 ms
  return p;
}

TEST(CommandGate, DefaultParamsAreValidAndBadOnesNameTheField) {
  EXPECT_NO_THROW(CommandGateParams{}.validate());
  CommandGateParams p;
  p.max_force_kN = 0.0;
  try {
    p.validate();
    FAIL() << "a zero force range was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_force_kN"), std::string::npos) << e.what();
  }
  p = CommandGateParams{};
  p.max_rate_kN_per_s = std::numeric_limits<double>::infinity();
  EXPECT_THROW(CommandGate(kRun, p), std::invalid_argument);
}

TEST(CommandGate, RefusesAnotherRunsCommandEvenFirst) {
  CommandGate gate(kRun, params());
  const auto r = gate.check(from(1, kRun + 1), true, 10.0, 0.0);
  EXPECT_EQ(r.verdict, GateVerdict::RefusedRun);
  EXPECT_FALSE(r.applies());
  EXPECT_FALSE(gate.pinned()) << "another run's command must not name the CCU";
  EXPECT_EQ(gate.counts().refused_run, 1u);
}

TEST(CommandGate, TakesOnlyTheWriterOfTheFirstAcceptedCommand) {
  CommandGate gate(kRun, params());
  EXPECT_EQ(gate.check(from(1), true, 10.0, 0.000).verdict, GateVerdict::Accepted);
  EXPECT_EQ(gate.check(from(2), true, 10.0, 0.005).verdict, GateVerdict::RefusedSource);
  EXPECT_EQ(gate.check(from(2), false, 0.0, 0.005).verdict, GateVerdict::RefusedSource) << "a release from another writer";
  EXPECT_EQ(gate.check(from(1), true, 12.0, 0.005).verdict, GateVerdict::Accepted);
  EXPECT_EQ(gate.counts().accepted, 2u);
  EXPECT_EQ(gate.counts().refused_source, 2u);
  EXPECT_EQ(gate.counts().refused(), 2u);
}

TEST(CommandGate, PinsOnlyAWriterAnnouncedAsThisRunsCcu) {
  CommandGate gate(kRun, params());
  // An intruder that knows the run id but is not the CCU comes first: refused, nothing pinned.
  EXPECT_EQ(gate.check(from(9, kRun, false), true, 77.7, 0.0).verdict, GateVerdict::RefusedSource);
  EXPECT_FALSE(gate.pinned());
  EXPECT_EQ(gate.check(from(1), true, 10.0, 0.0).verdict, GateVerdict::Accepted);
  EXPECT_TRUE(gate.pinned());
  EXPECT_EQ(gate.check(from(9, kRun, false), true, 77.7, 0.005).verdict, GateVerdict::RefusedSource);
  EXPECT_EQ(gate.counts().refused_source, 2u);
}

TEST(CommandGate, ClampsForceToTheRatedRange) {
  CommandGate gate(kRun, params());
  auto r = gate.check(from(1), true, 77.7, 0.0);  // the intruder's force of issue 17
  EXPECT_EQ(r.verdict, GateVerdict::Clamped);
  EXPECT_DOUBLE_EQ(r.force_kN, 40.0);
  r = gate.check(from(1), true, -5.0, 0.010);
  EXPECT_EQ(r.verdict, GateVerdict::Clamped);
  EXPECT_DOUBLE_EQ(r.force_kN, 0.0);
  EXPECT_EQ(gate.counts().clamped, 2u);
}

TEST(CommandGate, LimitsTheRateOfChangeBetweenCommandPeriods) {
  CommandGate gate(kRun, params());
  EXPECT_DOUBLE_EQ(gate.check(from(1), true, 0.0, 0.0).force_kN, 0.0);
  // Full range in one 5 ms period is allowed (a CCU step), faster is not.
  EXPECT_DOUBLE_EQ(gate.check(from(1), true, 40.0, 0.005).force_kN, 40.0);
  auto r = gate.check(from(1), true, 0.0, 0.006);  // 1 ms later: at most 8 kN down
  EXPECT_EQ(r.verdict, GateVerdict::Clamped);
  EXPECT_DOUBLE_EQ(r.force_kN, 32.0);
  r = gate.check(from(1), true, 0.0, 0.006);  // no time passed: no change at all
  EXPECT_DOUBLE_EQ(r.force_kN, 32.0);
  r = gate.check(from(1), true, 40.0, 0.005);  // time going backwards counts as none
  EXPECT_DOUBLE_EQ(r.force_kN, 32.0);
}

TEST(CommandGate, ReleaseRestartsTheRateFromZero) {
  CommandGate gate(kRun, params());
  gate.check(from(1), true, 40.0, 0.0);
  EXPECT_EQ(gate.check(from(1), false, 0.0, 0.001).verdict, GateVerdict::Accepted);
  EXPECT_DOUBLE_EQ(gate.check(from(1), true, 40.0, 0.002).force_kN, 8.0);
}

TEST(CommandGate, RefusesAForceThatIsNoNumber) {
  CommandGate gate(kRun, params());
  EXPECT_EQ(gate.check(from(1), true, std::nan(""), 0.0).verdict, GateVerdict::RefusedValue);
  EXPECT_FALSE(gate.pinned());
  EXPECT_EQ(gate.check(from(1), true, std::numeric_limits<double>::infinity(), 0.0).verdict, GateVerdict::RefusedValue);
  EXPECT_EQ(gate.counts().refused_value, 2u);
}

}  // namespace

// A hot-standby run (issue 16): the gate pins the first two writers announced as this run's
// CCUs, refuses a third, and limits a takeover's first command to the rated range only (the
// other CCU's period clock is its own).
namespace {

TEST(CommandGate, WithAStandbyPinsTwoCcuWritersAndNoThird) {
  CommandGateParams p = params();
  p.max_sources = 2;
  CommandGate gate(kRun, p);
  EXPECT_EQ(gate.check(from(1), true, 10.0, 0.100).verdict, GateVerdict::Accepted);
  EXPECT_FALSE(gate.pinned());
  EXPECT_EQ(gate.check(from(2), true, 10.0, 0.100).verdict, GateVerdict::Accepted);
  EXPECT_TRUE(gate.pinned());
  EXPECT_EQ(gate.check(from(3), true, 10.0, 0.105).verdict, GateVerdict::RefusedSource);
  EXPECT_EQ(gate.check(from(4, kRun, false), true, 10.0, 0.105).verdict, GateVerdict::RefusedSource);
  EXPECT_EQ(gate.check(from(1), true, 10.0, 0.105).verdict, GateVerdict::Accepted);
  EXPECT_EQ(gate.counts().refused_source, 2u);
  // One source only (no standby): the second announced writer is refused, as before.
  CommandGate single(kRun, params());
  EXPECT_EQ(single.check(from(1), true, 10.0, 0.100).verdict, GateVerdict::Accepted);
  EXPECT_EQ(single.check(from(2), true, 10.0, 0.105).verdict, GateVerdict::RefusedSource);
}

TEST(CommandGate, ATakeoverIsLimitedToTheRangeNotByTheOtherClock) {
  CommandGateParams p = params();
  p.max_rate_kN_per_s = 100.0;  // 0.5 kN per 5 ms
  p.max_sources = 2;
  CommandGate gate(kRun, p);
  EXPECT_EQ(gate.check(from(1), true, 10.0, 1.000).verdict, GateVerdict::Accepted);
  // The standby's clock is 3 ms behind: its command names an earlier period. Without the
  // takeover rule no change would be allowed; with it, the range is the only limit.
  const auto r = gate.check(from(2), true, 12.0, 0.997);
  EXPECT_EQ(r.verdict, GateVerdict::Accepted);
  EXPECT_DOUBLE_EQ(r.force_kN, 12.0);
  // Then the rate holds again for that writer.
  const auto next = gate.check(from(2), true, 20.0, 1.002);
  EXPECT_EQ(next.verdict, GateVerdict::Clamped);
  EXPECT_NEAR(next.force_kN, 12.5, 1e-9);
  EXPECT_THROW(
      [] {
        CommandGateParams bad;
        bad.max_sources = 3;
        bad.validate();
      }(),
      std::invalid_argument);
}

}  // namespace
