// Unit tests of the calibrator's pieces against hand-worked cases.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <stdexcept>
#include <string>

#include "bbw/calibration/bounded_lsq.hpp"
#include "bbw/calibration/config.hpp"
#include "bbw/calibration/cycle_detector.hpp"
#include "bbw/calibration/sample_store.hpp"
#include "bbw/model/effect_terms.hpp"
#include "bbw/model/maxwell_slip.hpp"

using namespace bbw::calibration;

TEST(MaxwellSlipElement, StickThenSlipThenReverse) {
  double pos = 0.0;  // element at x_i = 0, threshold 0.1
  EXPECT_DOUBLE_EQ(element_step(0.05, 0.1, pos), 0.5);  // stick: n = d / Delta
  EXPECT_DOUBLE_EQ(pos, 0.0);
  EXPECT_DOUBLE_EQ(element_step(0.1, 0.1, pos), 1.0);   // reaches threshold: slips
  EXPECT_DOUBLE_EQ(element_step(0.3, 0.1, pos), 1.0);   // keeps slipping, position follows
  EXPECT_NEAR(pos, 0.2, 1e-15);
  EXPECT_NEAR(element_step(0.25, 0.1, pos), 0.5, 1e-12);  // reversal: sticks again, n falls linearly
  EXPECT_NEAR(element_step(0.15, 0.1, pos), -0.5, 1e-12);
  EXPECT_DOUBLE_EQ(element_step(0.0, 0.1, pos), -1.0);  // slips downwards
  EXPECT_NEAR(pos, 0.1, 1e-15);
}

TEST(MaxwellSlipElement, LoopIsClosedAndBounded) {
  // Sum of elements over a periodic input: the friction loop closes after the first period
  // and stays within +/- sum K_i Delta_i.
  const double delta[3] = {0.02, 0.05, 0.1};
  const double k[3] = {10.0, 5.0, 2.0};  // kN/rev: amplitudes 0.2, 0.25, 0.2 kN
  double pos[3] = {0.0, 0.0, 0.0};
  std::vector<double> f1, f2;
  for (int period = 0; period < 3; ++period) {
    for (int s = 0; s < 400; ++s) {
      const double x = 0.5 * std::sin(2.0 * M_PI * s / 400.0);
      const double f = elements_step(x, delta, pos, 3, k, nullptr);
      EXPECT_LE(std::fabs(f), 0.65 + 1e-12);
      if (period == 1) f1.push_back(f);
      if (period == 2) f2.push_back(f);
    }
  }
  for (std::size_t s = 0; s < f1.size(); ++s) EXPECT_NEAR(f1[s], f2[s], 1e-12);
  // At the top of the stroke all elements slip upward: friction = +0.65.
  EXPECT_NEAR(f2[100], 0.65, 1e-12);
}

TEST(Thresholds, EvenAndGeometric) {
  double even[4], geo[4];
  thresholds(4, 0.4, false, 0.5, even);
  thresholds(4, 0.4, true, 0.5, geo);
  EXPECT_DOUBLE_EQ(even[0], 0.1);
  EXPECT_DOUBLE_EQ(even[3], 0.4);
  EXPECT_DOUBLE_EQ(geo[3], 0.4);
  EXPECT_DOUBLE_EQ(geo[2], 0.2);
  EXPECT_DOUBLE_EQ(geo[0], 0.05);
}

TEST(CycleDetector, FiresWhereFallingTurnsToRising) {
  CycleDetector d(3, 0.0);
  // Falling for 10 samples, minimum at index 10, then rising.
  std::vector<int> fired;
  double min_at_fire = -1.0;
  for (int i = 0; i < 25; ++i) {
    const double x = std::fabs(i - 10.0);
    if (d.update(x)) {
      fired.push_back(i);
      min_at_fire = d.recent_min_rev();
    }
  }
  // eq. 6 with n0 = 3: x(i) > x(i-3) and x(i-3) < x(i-6). First true at i = 12
  // (x(12)=2 > x(9)=1, x(9)=1 < x(6)=4).
  ASSERT_EQ(fired.size(), 1u);
  EXPECT_EQ(fired[0], 12);
  EXPECT_NEAR(min_at_fire, 0.0, 1e-12);
}

TEST(CycleDetector, NoisyMinimumFiresOncePerCycleWithMargin) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.002);
  CycleDetector paper(10, 0.0), robust(10, 0.02);
  int paper_starts = 0, robust_starts = 0;
  const int period = 1000;
  for (int i = 0; i < 5 * period; ++i) {
    const double x = 1.0 - std::cos(2.0 * M_PI * i / period) + noise(rng);  // minima at multiples of period
    paper_starts += paper.update(x) ? 1 : 0;
    robust_starts += robust.update(x) ? 1 : 0;
  }
  // Five minima (i = 0, 1000, ..., 4000): the hysteresis detector fires once after each.
  EXPECT_EQ(robust_starts, 5);
  // The paper's rule re-fires on noise near flat minima; the calibrator's "at least L samples
  // since the last start" rule is what protects it.
  EXPECT_GE(paper_starts, 4);
}

TEST(SampleStore, FillsThenDropsTheClosestPairsSampleJ) {
  // L = 4, ranges 1 so distances are plain Euclidean in (x, f).
  SampleStore s(4, 1, 1.0, 1.0, DropRule::DropJ);
  const double n = 0.0;
  s.add(0.0, 0.0, &n);
  s.add(1.0, 0.0, &n);
  s.add(1.1, 0.0, &n);  // close to the previous one: pair (2,3) in 1-based slots is the closest
  s.add(3.0, 0.0, &n);
  ASSERT_EQ(s.size(), 4u);
  s.add(5.0, 0.0, &n);  // slot L+1; closest pair is slots 2-3 (distance 0.1): j = 2, sample 2 dropped
  ASSERT_EQ(s.size(), 4u);
  EXPECT_DOUBLE_EQ(s.x_rev(0), 0.0);
  EXPECT_DOUBLE_EQ(s.x_rev(1), 1.1);
  EXPECT_DOUBLE_EQ(s.x_rev(2), 3.0);
  EXPECT_DOUBLE_EQ(s.x_rev(3), 5.0);
  s.add(5.05, 0.0, &n);  // closest to its predecessor: j = L, the new sample is not recorded
  EXPECT_DOUBLE_EQ(s.x_rev(3), 5.0);
  EXPECT_EQ(s.dropped(), 2u);
}

TEST(SampleStore, OtherReadingDropsSampleJPlus1) {
  SampleStore s(4, 1, 1.0, 1.0, DropRule::DropJPlus1);
  const double n = 0.0;
  for (double x : {0.0, 1.0, 1.1, 3.0, 5.0}) s.add(x, 0.0, &n);
  EXPECT_DOUBLE_EQ(s.x_rev(1), 1.0);
  EXPECT_DOUBLE_EQ(s.x_rev(2), 3.0);
}

TEST(SampleStore, NormalisesByRangesAndKeepsRows) {
  // With a force range 100x the position range, force differences count 100x less.
  SampleStore s(3, 2, 1.0, 100.0, DropRule::DropJ);
  const double r0[2] = {0, 1}, r1[2] = {2, 3}, r2[2] = {4, 5}, r3[2] = {6, 7};
  s.add(0.0, 0.0, r0);
  s.add(0.5, 0.0, r1);   // d = 0.5
  s.add(0.6, 40.0, r2);  // d = sqrt(0.01 + 0.16) = 0.41
  s.add(2.0, 40.0, r3);  // d = 1.4 -> closest is pair 2-3 (0.41), sample 2 dropped
  EXPECT_DOUBLE_EQ(s.x_rev(1), 0.6);
  EXPECT_FLOAT_EQ(s.n_row(1)[0], 4.0f);
  EXPECT_FLOAT_EQ(s.n_row(2)[1], 7.0f);
  EXPECT_DOUBLE_EQ(s.min_x_rev(), 0.0);
  EXPECT_DOUBLE_EQ(s.max_x_rev(), 2.0);
}

TEST(BoundedLeastSquares, UnboundedMatchesExactSolution) {
  // G = [[4,1],[1,3]], h = G * [1, -2]
  const double G[4] = {4, 1, 1, 3};
  const double h[2] = {4 * 1 + 1 * -2, 1 * 1 + 3 * -2};
  BoundedLeastSquares s(4);
  double t[2];
  ASSERT_TRUE(s.solve_unbounded(G, h, 2, t));
  EXPECT_NEAR(t[0], 1.0, 1e-12);
  EXPECT_NEAR(t[1], -2.0, 1e-12);
}

TEST(BoundedLeastSquares, NonNegativeMatchesBruteForce) {
  // Random problems: compare with enumeration of all active sets.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  BoundedLeastSquares s(6);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 5, rows = 12;
    std::vector<double> A(rows * n), b(rows);
    for (auto& v : A) v = g(rng);
    for (auto& v : b) v = g(rng);
    std::vector<double> G(n * n, 0.0), h(n, 0.0);
    for (int r = 0; r < rows; ++r) {
      for (int i = 0; i < n; ++i) {
        h[i] += A[r * n + i] * b[r];
        for (int j = 0; j < n; ++j) G[i * n + j] += A[r * n + i] * A[r * n + j];
      }
    }
    const char nonneg[5] = {0, 1, 1, 1, 0};  // first and last free
    double t[5];
    ASSERT_TRUE(s.solve(G.data(), h.data(), nonneg, n, t));
    auto cost = [&](const double* th) {
      double c = 0.0;
      for (int r = 0; r < rows; ++r) {
        double e = -b[r];
        for (int i = 0; i < n; ++i) e += A[r * n + i] * th[i];
        c += e * e;
      }
      return c;
    };
    // Brute force: for every subset of the constrained variables fixed at 0, solve the rest.
    double best = 1e300;
    BoundedLeastSquares sub(6);
    for (int mask = 0; mask < 8; ++mask) {
      const int idx[3] = {1, 2, 3};
      std::vector<double> Gs = G, hs = h;
      for (int q = 0; q < 3; ++q) {
        if (mask & (1 << q)) {  // variable idx[q] fixed at 0: decouple it
          const int v = idx[q];
          for (int j = 0; j < n; ++j) Gs[v * n + j] = Gs[j * n + v] = 0.0;
          Gs[v * n + v] = 1.0;
          hs[v] = 0.0;
        }
      }
      double th[5];
      ASSERT_TRUE(sub.solve_unbounded(Gs.data(), hs.data(), n, th));
      bool feasible = th[1] >= -1e-12 && th[2] >= -1e-12 && th[3] >= -1e-12;
      if (feasible) best = std::min(best, cost(th));
    }
    EXPECT_GE(t[1], 0.0);
    EXPECT_GE(t[2], 0.0);
    EXPECT_GE(t[3], 0.0);
    EXPECT_NEAR(cost(t), best, 1e-9 * std::max(1.0, best));
  }
}

// The effect terms' bounds are one copy: validate() names the term bound a value breaks (the same
// bounds the YAML loader and the wire codec check through).
TEST(EffectTerms, ValidateNamesTheTermBoundItBreaks) {
  struct Case {
    void (*spoil)(CalibratorConfig&);
    const char* key;
    const char* rule;
  };
  for (const Case& k : {Case{[](CalibratorConfig& c) { c.backlash_width_rev = 0.6; }, "backlash_width_rev", "must be in [0, 0.5]"},
                        Case{[](CalibratorConfig& c) { c.force_delay_s = -0.001; }, "force_delay_s", "must be in [0, 0.05]"},
                        Case{[](CalibratorConfig& c) { c.load_friction_gain = 11.0; }, "load_friction_gain", "must be in [0, 10]"},
                        Case{[](CalibratorConfig& c) { c.load_friction_reference_kN = 0.0; }, "load_friction_reference_kN", "must be > 0"},
                        Case{[](CalibratorConfig& c) { c.viscous_speed_scale_rev_per_s = 0.0; }, "viscous_speed_scale_rev_per_s", "must be > 0"},
                        Case{[](CalibratorConfig& c) { c.load_cell_offset_kN_per_C = 1.5; }, "load_cell_offset_kN_per_C", "must be in [-1, 1]"},
                        Case{[](CalibratorConfig& c) { c.load_cell_offset_reference_C = 200.0; }, "load_cell_offset_reference_C", "must be in [-50, 150]"}}) {
    CalibratorConfig c;
    k.spoil(c);
    try {
      c.validate();
      ADD_FAILURE() << k.key << " accepted";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(k.key), std::string::npos) << what;
      EXPECT_NE(what.find(k.rule), std::string::npos) << what;
    }
  }
  EXPECT_NO_THROW(CalibratorConfig{}.validate());
}

// Only the viscous term adds a regressor column; the others act on the position, the element
// regressors or the reading.
TEST(EffectTerms, OnlyTheViscousTermAddsAColumn) {
  CalibratorConfig c;
  EXPECT_EQ(c.effect_columns(), 0);
  c.force_delay_s = 0.005;
  c.backlash_width_rev = 0.05;
  c.load_friction_gain = 0.9;
  c.load_cell_offset_kN_per_C = 0.02;
  EXPECT_EQ(c.effect_columns(), 0);
  c.viscous_friction = true;
  EXPECT_EQ(c.effect_columns(), 1);
  EXPECT_EQ(std::tuple_size_v<EffectTerms>, 5u);
}
