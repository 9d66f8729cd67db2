// The Magic Formula against its own closed forms: the peak is D = (PDX1 + PDX2 dfz) lambda_mu Fz,
// reached where C atan(...) = pi/2; combined slip only reduces a force; the force at a slip is odd.
#include <gtest/gtest.h>

#include <cmath>

#include "bbw/vehicle/tyre.hpp"

using namespace bbw::vehicle;

TEST(Tyre, PeakIsTheMagicFormulasD) {
  const TyreParams p;
  for (double scale : {1.0, 0.5, 0.1}) {
    const PeakMu peak = peak_longitudinal_mu(p, p.nominal_load_N, scale, scale);
    EXPECT_NEAR(peak.mu, p.pdx1 * scale, 1e-6) << scale;
    // Scaling peak and stiffness alike keeps the slip at the peak.
    EXPECT_NEAR(peak.slip, peak_longitudinal_mu(p, p.nominal_load_N, 1.0, 1.0).slip, 1e-4);
  }
}

TEST(Tyre, PeakFallsWithLoadByPDX2) {
  const TyreParams p;
  const double fz = 2.0 * p.nominal_load_N;  // dfz = 1
  EXPECT_NEAR(peak_longitudinal_mu(p, fz, 1.0, 1.0).mu, p.pdx1 + p.pdx2, 1e-6);
  EXPECT_LT(peak_longitudinal_mu(p, fz, 1.0, 1.0).mu, peak_longitudinal_mu(p, 0.5 * fz, 1.0, 1.0).mu);
}

TEST(Tyre, SlidingIsBelowThePeakAndMatchesTheFormula) {
  const TyreParams p;
  const double fz = p.nominal_load_N;
  const double B = p.pkx1 / (p.pcx1 * p.pdx1);
  const double x = B * 1.0;
  const double expect = p.pdx1 * std::sin(p.pcx1 * std::atan(x - p.pex1 * (x - std::atan(x))));
  EXPECT_NEAR(sliding_mu(p, fz, 1.0, 1.0), expect, 1e-9);
  EXPECT_LT(sliding_mu(p, fz, 1.0, 1.0), 0.8 * p.pdx1);
}

TEST(Tyre, ForcesAreOddInSlipAndCombinedSlipOnlyReduces) {
  const TyreParams p;
  const double fz = 4000.0;
  const TyreForce a = tyre_force(p, fz, -0.1, 0.0, 1.0, 1.0);
  const TyreForce b = tyre_force(p, fz, 0.1, 0.0, 1.0, 1.0);
  EXPECT_NEAR(a.longitudinal_N, -b.longitudinal_N, 1e-9);
  EXPECT_LT(a.longitudinal_N, 0.0);
  EXPECT_DOUBLE_EQ(a.lateral_N, 0.0);
  const TyreForce c = tyre_force(p, fz, 0.0, 0.05, 1.0, 1.0);
  EXPECT_LT(c.lateral_N, 0.0);  // slip angle to the left: force to the right
  const TyreForce both = tyre_force(p, fz, -0.1, 0.05, 1.0, 1.0);
  EXPECT_LT(std::abs(both.longitudinal_N), std::abs(a.longitudinal_N));
  EXPECT_LT(std::abs(both.lateral_N), std::abs(c.lateral_N));
  EXPECT_GT(std::abs(both.lateral_N), 0.0);
}

TEST(Tyre, SlopeMatchesAFiniteDifference) {
  const TyreParams p;
  for (double k : {-0.3, -0.05, 0.0, 0.02, 0.2}) {
    const double h = 1e-6;
    const double fd = (tyre_force(p, 3000, k + h, 0.0, 0.8, 0.8).longitudinal_N -
                       tyre_force(p, 3000, k - h, 0.0, 0.8, 0.8).longitudinal_N) / (2 * h);
    EXPECT_NEAR(tyre_force(p, 3000, k, 0.0, 0.8, 0.8).dFx_dkappa_N, fd, 1e-3 * std::abs(fd) + 1e-3) << k;
  }
}

TEST(Tyre, NoLoadNoForce) {
  const TyreParams p;
  const TyreForce f = tyre_force(p, 0.0, -0.2, 0.1, 1.0, 1.0);
  EXPECT_EQ(f.longitudinal_N, 0.0);
  EXPECT_EQ(f.lateral_N, 0.0);
}
