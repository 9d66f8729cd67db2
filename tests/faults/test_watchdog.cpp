// The corner's CCU watchdog: hold, then the default clamp force, never a release.
#include <gtest/gtest.h>

#include <cmath>

#include "bbw/faults/ccu_watchdog.hpp"

using namespace bbw::faults;

TEST(CcuWatchdog, DefaultParametersAreValidAndInvalidOnesNameTheField) {
  EXPECT_NO_THROW(CcuWatchdogParams{}.validate());
  CcuWatchdogParams p;
  p.default_clamp_force_kN = 0.0;
  try {
    p.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("default_clamp_force_kN"), std::string::npos);
  }
  p = {};
  p.timeout_s = -1.0;
  EXPECT_THROW(CcuWatchdog{p}, std::invalid_argument);
}

TEST(CcuWatchdog, HoldsThenRampsToTheDefaultAndNeverReleases) {
  CcuWatchdogParams p;
  p.timeout_s = 0.02;
  p.hold_s = 0.5;
  p.default_clamp_force_kN = 8.0;
  p.ramp_kN_per_s = 40.0;
  CcuWatchdog w(p);
  EXPECT_EQ(w.at(0.0).mode, WatchdogMode::NoCommandYet);
  EXPECT_FALSE(w.at(0.0).force_command_kN.has_value());
  w.on_command(1.0, 24.0);
  EXPECT_EQ(w.at(1.01).mode, WatchdogMode::Normal);
  EXPECT_EQ(w.at(1.03).mode, WatchdogMode::Holding);
  EXPECT_DOUBLE_EQ(*w.at(1.5).force_command_kN, 24.0);
  const auto d = w.at(1.52 + 0.1);
  EXPECT_EQ(d.mode, WatchdogMode::Default);
  EXPECT_NEAR(*d.force_command_kN, 24.0 - 4.0, 1e-9);
  EXPECT_DOUBLE_EQ(*w.at(5.0).force_command_kN, 8.0);
  for (double t = 1.0; t < 20.0; t += 0.001) ASSERT_GE(*w.at(t).force_command_kN, 8.0);
  // A released brake (command 0) is applied to the default when the CCU is lost.
  w.on_command(30.0, 0.0);
  EXPECT_DOUBLE_EQ(*w.at(40.0).force_command_kN, 8.0);
  // The CCU speaks again.
  w.on_command(41.0, 12.0);
  EXPECT_EQ(w.at(41.001).mode, WatchdogMode::Normal);
  EXPECT_DOUBLE_EQ(*w.at(41.001).force_command_kN, 12.0);
}

TEST(CcuWatchdog, IgnoresCorruptAndOutOfOrderCommands) {
  CcuWatchdog w(CcuWatchdogParams{});
  w.on_command(1.0, 10.0);
  w.on_command(1.001, std::nan(""));
  w.on_command(0.5, 30.0);
  EXPECT_DOUBLE_EQ(*w.at(1.002).force_command_kN, 10.0);
}

// Realtime on a loaded machine: the corner's own process stalled 60 ms (its periods begin late and
// are caught up one after another, each reporting how late it began). It could take no command
// then, so the stall is not the CCU's silence; the CCU's next command has the timeout, counted
// from when the corner ran again. Without the exclusion, the catch-up alone enters the hold.
TEST(CcuWatchdog, ACornersOwnStallIsNotTheCcusSilenceAndCountsOnce) {
  for (const bool exclude : {true, false}) {
    CcuWatchdogParams p;
    p.exclude_own_stalls = exclude;
    CcuWatchdog w(p);
    w.on_command(1.000, 10.0);
    // Period k was due at 1.005; the corner ran again at 1.065. Periods k..k+12 are caught up at
    // once, each reporting [its due time, 1.065]: one stall of 60 ms.
    for (int i = 0; i <= 12; ++i) w.on_own_stall(1.005 + 0.005 * i, 1.065);
    const auto caught_up = w.at(1.070);
    if (exclude) {
      EXPECT_EQ(caught_up.mode, WatchdogMode::Normal);
      EXPECT_EQ(w.at(1.000 + 0.060 + 0.0199).mode, WatchdogMode::Normal);
      // Counted once: 20 ms of running time after the last command is the timeout.
      EXPECT_EQ(w.at(1.000 + 0.060 + 0.0201).mode, WatchdogMode::Holding);
    } else {
      EXPECT_EQ(caught_up.mode, WatchdogMode::Holding);
    }
  }
}

TEST(CcuWatchdog, StallsBeforeTheLastCommandOrAlreadyCountedDoNotDelayTheHold) {
  CcuWatchdog w(CcuWatchdogParams{});
  w.on_own_stall(0.5, 0.6);  // before any command: nothing to excuse
  w.on_command(1.000, 10.0);
  w.on_own_stall(0.9, 1.004);  // ended 4 ms after the command: 4 ms counted
  w.on_own_stall(0.95, 1.004);  // the same stall reported again: nothing more
  EXPECT_EQ(w.at(1.0239).mode, WatchdogMode::Normal);
  EXPECT_EQ(w.at(1.0241).mode, WatchdogMode::Holding);
  // A dead CCU is still found by a corner that is always a little late: a period of 5 ms begun
  // 1 ms late each time counts 1 ms in 5, so the hold comes after 25 ms, not never.
  CcuWatchdog v(CcuWatchdogParams{});
  v.on_command(2.000, 10.0);
  double t = 2.000;
  while (v.at(t).mode == WatchdogMode::Normal && t < 3.0) {
    t += 0.005;
    v.on_own_stall(t, t + 0.001);
  }
  EXPECT_NEAR(t - 2.000, 0.025, 0.0051);
  // A new command ends the excuse: the next silence counts from it.
  v.on_command(3.000, 5.0);
  EXPECT_EQ(v.at(3.0201).mode, WatchdogMode::Holding);
}
