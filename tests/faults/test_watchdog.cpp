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
