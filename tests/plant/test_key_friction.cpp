#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "bbw/plant/key_friction.hpp"

using bbw::plant::KeyFriction;
using bbw::plant::KeyFrictionParams;

TEST(KeyFriction, HalfWidthIsTheConfiguredSum) {
  KeyFrictionParams p;
  p.half_width_kN = 1.3;
  const KeyFriction f(p);
  EXPECT_EQ(f.elements(), 40u);
  EXPECT_NEAR(f.half_width_kN(), 1.3, 1e-12);
}

TEST(KeyFriction, ThresholdsAreUnevenLogNormalAndSeeded) {
  KeyFrictionParams p;
  p.elements = 60;
  const KeyFriction a(p), b(p);
  EXPECT_EQ(a.thresholds_rev(), b.thresholds_rev());
  p.structure_seed += 1;
  const KeyFriction c(p);
  EXPECT_NE(a.thresholds_rev(), c.thresholds_rev());
  // Log-thresholds: mean near log(median), spread near the configured sigma.
  std::vector<double> logs;
  for (const double d : a.thresholds_rev()) logs.push_back(std::log(d));
  const double mean = std::accumulate(logs.begin(), logs.end(), 0.0) / logs.size();
  double var = 0.0;
  for (const double l : logs) var += (l - mean) * (l - mean);
  const double sd = std::sqrt(var / (logs.size() - 1));
  EXPECT_NEAR(mean, std::log(p.threshold_median_rev), 0.25);
  EXPECT_NEAR(sd, p.threshold_log_sigma, 0.2);
  // Not evenly spaced like the calibrator's i/M * Delta_max: spacings vary a lot.
  const auto& d = a.thresholds_rev();
  double min_gap = 1e9, max_gap = 0.0;
  for (std::size_t i = 1; i < d.size(); ++i) {
    min_gap = std::min(min_gap, d[i] - d[i - 1]);
    max_gap = std::max(max_gap, d[i] - d[i - 1]);
  }
  EXPECT_GT(max_gap, 5.0 * min_gap);
}

TEST(KeyFriction, PreSlidingLoopIsBoundedClosedAndSaturates) {
  const KeyFrictionParams p;
  KeyFriction f(p);
  const double big = 5.0 * f.thresholds_rev().back();
  f.reset(1.0);
  EXPECT_DOUBLE_EQ(f.force_kN(), 0.0);
  // Small motion: stick, force proportional to travel with the total stiffness.
  double k_total = 0.0;
  for (const double k : f.stiffness_kN_per_rev()) k_total += k;
  const double small = 0.1 * f.thresholds_rev().front();
  EXPECT_NEAR(f.step(1.0 + small), k_total * small, 1e-9);
  // Far up: every element slips, force at +half-width; far down: -half-width.
  for (double x = 1.0; x <= 1.0 + big; x += 1e-3) f.step(x);
  EXPECT_NEAR(f.force_kN(), p.half_width_kN, 1e-9);
  std::vector<double> down;
  for (double x = 1.0 + big; x >= 1.0; x -= 1e-3) down.push_back(f.step(x));
  EXPECT_NEAR(f.force_kN(), -p.half_width_kN, 1e-9);
  // Back up along the same path: a loop (rising values differ from falling ones) that
  // closes at the top.
  std::vector<double> up;
  for (double x = 1.0; x <= 1.0 + big + 1e-9; x += 1e-3) up.push_back(f.step(x));
  EXPECT_NEAR(up.back(), p.half_width_kN, 1e-9);
  const std::size_t mid = up.size() / 8;
  EXPECT_GT(up[mid] - down[down.size() - 1 - mid], 0.5 * p.half_width_kN);
  for (const double v : up) EXPECT_LE(std::abs(v), p.half_width_kN + 1e-12);
}
