// The characteristic curve: clamp force as a cubic in actuator position.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace bbw::model {

struct Curve {
  double a = 0.0;  // kN/rev^3
  double b = 0.0;  // kN/rev^2
  double c = 0.0;  // kN/rev
  double d = 0.0;  // kN

  double force_kN(double x_rev) const { return ((a * x_rev + b) * x_rev + c) * x_rev + d; }
  // The cubic's local minimum (where its slope 3a x^2 + 2b x + c is 0 and rising), or -inf. Below
  // it a cubic fitted over the caliper's range rises again as the position falls.
  double local_min_rev() const {
    if (a == 0.0) return b > 0.0 ? -c / (2.0 * b) : -std::numeric_limits<double>::infinity();
    const double disc = b * b - 3.0 * a * c;
    if (!(disc > 0.0)) return -std::numeric_limits<double>::infinity();
    return (-b + std::sqrt(disc)) / (3.0 * a);
  }
  // The least force over [lo_rev, hi_rev]: at an end or at the local minimum.
  double least_kN(double lo_rev, double hi_rev) const {
    double f = std::min(force_kN(lo_rev), force_kN(hi_rev));
    const double x_min = local_min_rev();
    if (x_min > lo_rev && x_min < hi_rev) f = std::min(f, force_kN(x_min));
    return f;
  }
};

}  // namespace bbw::model

// The names where they lived before model/ existed (bbw::calibration), so code written against them
// keeps compiling; new code says bbw::model.
namespace bbw::calibration {
using model::Curve;
}  // namespace bbw::calibration
