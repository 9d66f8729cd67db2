#include "bbw/analysis/effects.hpp"

#include <gtest/gtest.h>

using namespace bbw::analysis;

TEST(Effects, PlayOperatorHoldsInsideTheBand) {
  PlayOperator p(0.2);
  EXPECT_DOUBLE_EQ(p.step(0.0), 0.0);
  EXPECT_DOUBLE_EQ(p.step(0.05), 0.0);   // inside +/- 0.1
  EXPECT_DOUBLE_EQ(p.step(0.3), 0.2);    // pushed from below
  EXPECT_DOUBLE_EQ(p.step(0.25), 0.2);   // reversal: held
  EXPECT_DOUBLE_EQ(p.step(0.0), 0.1);    // pushed from above
  EXPECT_THROW(PlayOperator(-1.0), std::invalid_argument);
}

TEST(Effects, FirstOrderLagStepResponse) {
  FirstOrderLag lag(0.5);
  lag.reset(0.0);
  double y = 0.0;
  for (int k = 0; k < 500; ++k) y = lag.step(1.0, 0.001);
  EXPECT_NEAR(y, 1.0 - std::exp(-1.0), 1e-9);
  EXPECT_THROW(FirstOrderLag(0.0), std::invalid_argument);
}

TEST(Effects, CreepRegressorDecaysAfterAStep) {
  std::vector<double> u(3000, 1.0);
  u[0] = 0.0;
  const auto c = creep_regressor(u, 0.001, 1.0);
  EXPECT_NEAR(c[1], 1.0, 2e-3);
  EXPECT_NEAR(c[1001], std::exp(-1.0), 2e-3);
}

TEST(Effects, DelayShiftsByInterpolation) {
  std::vector<double> x;
  for (int k = 0; k < 100; ++k) x.push_back(k);
  const auto d = delayed(x, 0.001, 0.0025);
  EXPECT_DOUBLE_EQ(d[10], 7.5);
  EXPECT_DOUBLE_EQ(d[0], 0.0);
  const auto lead = delayed(x, 0.001, -0.002);
  EXPECT_DOUBLE_EQ(lead[10], 12.0);
  EXPECT_DOUBLE_EQ(lead[99], 99.0);
}

TEST(Effects, MaxwellSlipRegressorsSaturateAndReverse) {
  std::vector<double> x = {0.0, 0.05, 0.2, 0.5, 0.45, 0.0};
  std::vector<std::vector<double>> n;
  maxwell_slip_regressors(x, {0.1, 0.3}, n);
  EXPECT_DOUBLE_EQ(n[0][1], 0.5);
  EXPECT_DOUBLE_EQ(n[0][2], 1.0);
  EXPECT_DOUBLE_EQ(n[1][3], 1.0);
  EXPECT_DOUBLE_EQ(n[0][4], 0.5);   // reversal by 0.05 from slipping at +0.1
  EXPECT_DOUBLE_EQ(n[0][5], -1.0);
}
