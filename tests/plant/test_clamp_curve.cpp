#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "bbw/plant/clamp_curve.hpp"

using bbw::plant::ClampCurve;
using bbw::plant::ClampCurveParams;

namespace {

// The curve formula written out independently of the implementation.
double expected_force(const ClampCurveParams& p, double x, double T, double wear) {
  const double xc = p.contact_rev + p.contact_shift_rev_per_C * (T - p.reference_temperature_C) + wear;
  const double d = p.smoothing_rev * std::log(1.0 + std::exp((x - xc) / p.smoothing_rev));
  const double s = 1.0 + p.stiffness_change_per_C * (T - p.reference_temperature_C);
  return s * (p.exp_coefficient_kN * (std::exp(d / p.exp_length_rev) - 1.0) + p.linear_kN_per_rev * d);
}

}  // namespace

TEST(ClampCurve, MonotoneAndStiffeningEverywhere) {
  const ClampCurve c{ClampCurveParams{}};
  for (const double T : {28.0, 40.0, 54.0}) {
    double prev_f = c.force_kN(-1.0, T, 0.0);
    double prev_slope = c.slope_kN_per_rev(-1.0, T, 0.0);
    for (double x = -0.99; x <= 8.0; x += 0.01) {
      const double f = c.force_kN(x, T, 0.0);
      const double k = c.slope_kN_per_rev(x, T, 0.0);
      EXPECT_GT(f, prev_f) << "x=" << x;
      EXPECT_GE(k, prev_slope - 1e-12) << "x=" << x;  // convex: stiffening, no kink
      prev_f = f;
      prev_slope = k;
    }
    EXPECT_LT(c.force_kN(-0.5, T, 0.0), 1e-3);  // no force with an air gap
  }
}

TEST(ClampCurve, ReachesFortyToFiftyKiloNewtonNearSixToSevenRevolutions) {
  const ClampCurve c{ClampCurveParams{}};
  EXPECT_GT(c.force_kN(6.5, 40.0, 0.0), 40.0);
  EXPECT_LT(c.force_kN(6.5, 40.0, 0.0), 50.0);
  EXPECT_LT(c.force_kN(6.0, 40.0, 0.0), 45.0);
  EXPECT_GT(c.force_kN(7.0, 40.0, 0.0), 45.0);
}

TEST(ClampCurve, MatchesTheDocumentedFormulaAndItsSlope) {
  ClampCurveParams p;
  p.contact_shift_rev_per_C = 0.006;
  const ClampCurve c{p};
  for (double x = 0.0; x <= 7.0; x += 0.25) {
    for (const double T : {28.0, 54.0}) {
      EXPECT_NEAR(c.force_kN(x, T, 0.1), expected_force(p, x, T, 0.1), 1e-9);
      const double h = 1e-6;
      const double numeric = (c.force_kN(x + h, T, 0.1) - c.force_kN(x - h, T, 0.1)) / (2 * h);
      EXPECT_NEAR(c.slope_kN_per_rev(x, T, 0.1), numeric, 1e-5);
    }
  }
}

TEST(ClampCurve, IsNotACubic) {
  // The calibrator fits a cubic; the true curve must not be one, or it would fit exactly.
  const ClampCurve c{ClampCurveParams{}};
  const int n = 61;
  Eigen::MatrixXd a(n, 4);
  Eigen::VectorXd f(n);
  for (int i = 0; i < n; ++i) {
    const double x = 1.0 + 6.0 * i / (n - 1);
    a.row(i) << x * x * x, x * x, x, 1.0;
    f(i) = c.force_kN(x, 40.0, 0.0);
  }
  const Eigen::VectorXd coef = a.colPivHouseholderQr().solve(f);
  const double max_residual = (a * coef - f).cwiseAbs().maxCoeff();
  EXPECT_GT(max_residual, 0.02);  // kN: visible to a 0.27 kN-accurate calibrator budget
  EXPECT_LT(max_residual, 2.0);   // but a cubic is still a fair local model
}

TEST(ClampCurve, TemperatureMovesTheCurveByTheConfiguredAmount) {
  const ClampCurveParams p;
  const ClampCurve c{p};
  for (const double x : {3.0, 5.0, 6.0}) {
    const double diff = c.force_kN(x, 28.0, 0.0) - c.force_kN(x, 54.0, 0.0);
    EXPECT_NEAR(diff, expected_force(p, x, 28.0, 0) - expected_force(p, x, 54.0, 0), 1e-9);
  }
  // Defaults: "a few kN" at 5 rev between 28 and 54 C (paper Fig. 14), hotter is softer.
  const double d5 = c.force_kN(5.0, 28.0, 0.0) - c.force_kN(5.0, 54.0, 0.0);
  EXPECT_GT(d5, 2.0);
  EXPECT_LT(d5, 6.0);
  EXPECT_NEAR(c.contact_rev(54.0, 0.0) - c.contact_rev(28.0, 0.0), 26.0 * p.contact_shift_rev_per_C, 1e-12);
  EXPECT_NEAR(c.stiffness_scale(54.0) / c.stiffness_scale(28.0),
              (1 + 14 * p.stiffness_change_per_C) / (1 - 12 * p.stiffness_change_per_C), 1e-12);
}

TEST(ClampCurve, WearMovesTheContactPointAndShiftsTheCurve) {
  const ClampCurve c{ClampCurveParams{}};
  EXPECT_NEAR(c.contact_rev(40.0, 0.2) - c.contact_rev(40.0, 0.0), 0.2, 1e-12);
  // Worn pads: the same force needs 0.2 rev more travel.
  EXPECT_NEAR(c.force_kN(5.2, 40.0, 0.2), c.force_kN(5.0, 40.0, 0.0), 1e-9);
  EXPECT_LT(c.force_kN(5.0, 40.0, 0.2), c.force_kN(5.0, 40.0, 0.0) - 1.0);
}

TEST(ClampCurve, RejectsInvalidParameters) {
  ClampCurveParams p;
  p.exp_length_rev = 0.0;
  EXPECT_THROW(ClampCurve{p}, std::invalid_argument);
  p = {};
  p.stiffness_change_per_C = 0.5;
  EXPECT_THROW(ClampCurve{p}, std::invalid_argument);
}
