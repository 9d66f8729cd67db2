#include "bbw/faults/bridged_curve.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bbw::faults {

model::Curve bridge_curve(const model::Curve& fitted, const DataSpan& data, const plant::ClampCurve& eol,
                          double temperature_C, double from_rev, double to_rev) {
  if (!std::isfinite(from_rev) || !std::isfinite(to_rev) || !(from_rev < to_rev)) {
    throw std::invalid_argument("bridge_curve: the range must be finite with from_rev < to_rev");
  }
  constexpr int kPoints = 64;
  Eigen::Matrix<double, kPoints, 4> a;
  Eigen::Matrix<double, kPoints, 1> f;
  for (int k = 0; k < kPoints; ++k) {
    const double x = from_rev + (to_rev - from_rev) * k / (kPoints - 1);
    const double e = eol.force_kN(x, temperature_C, 0.0);
    double g = e;
    if (!data.empty()) {
      const double xb = std::clamp(x, data.lo_rev, data.hi_rev);
      g = fitted.force_kN(xb) + e - eol.force_kN(xb, temperature_C, 0.0);
    }
    a(k, 0) = x * x * x;
    a(k, 1) = x * x;
    a(k, 2) = x;
    a(k, 3) = 1.0;
    // Weighed as the force's own uncertainty grows (the end-of-line band's 0.01-0.03 F): each
    // point's error counts in proportion to 1 / (1 + F / 10 kN), so the released end, where a
    // fraction of a kN is a brake that drags or does not clamp, is not traded for the top.
    const double w = 1.0 / (1.0 + 0.1 * std::max(0.0, g));
    a.row(k) *= w;
    f(k) = g * w;
  }
  const Eigen::Vector4d c = a.colPivHouseholderQr().solve(f);
  return model::Curve{c(0), c(1), c(2), c(3)};
}

double eol_position_at(const plant::ClampCurve& eol, double force_kN, double temperature_C, double lo_rev,
                       double hi_rev) {
  auto below = [&](double x_rev) { return eol.force_kN(x_rev, temperature_C, 0.0) < force_kN; };
  if (!below(lo_rev)) return lo_rev;
  // The curve rises with the position: doubled until it reaches the force (at most hi_rev), then
  // bisected to 1e-6 rev.
  double lo = lo_rev, hi = std::min(hi_rev, std::max(2.0 * lo, lo + 1.0));
  while (hi < hi_rev && below(hi)) {
    lo = hi;
    hi = std::min(hi_rev, 2.0 * hi);
  }
  while (hi - lo > 1e-6) {
    const double mid = 0.5 * (lo + hi);
    (below(mid) ? lo : hi) = mid;
  }
  return hi;
}

}  // namespace bbw::faults
