// Maxwell-slip elements (eqs. 1-4): massless elasto-slip elements in parallel on input x.
// Pure arithmetic, no allocation: the caller owns the arrays.
#pragma once

#include <cmath>
#include <cstddef>

namespace bbw::model {

// Normalised deflection n_i of one element at input x, given its position x_i, and the
// element position after the sample (x_i stays when sticking, follows x at Delta_i when slipping).
// Reading chosen: the state update uses the current sample's deflection, so n_i is +/-1 exactly
// while slipping and the element position is x - sgn(d) Delta (eq. 2 with t+1 := t).
inline double element_step(double x_rev, double delta_rev, double& pos_rev) {
  const double d = x_rev - pos_rev;
  if (d >= delta_rev) {
    pos_rev = x_rev - delta_rev;
    return 1.0;
  }
  if (d <= -delta_rev) {
    pos_rev = x_rev + delta_rev;
    return -1.0;
  }
  return d / delta_rev;
}

// Steps all M elements at x; writes n_i into n_out (may be null). Returns sum K_i Delta_i n_i
// when k is non-null, else 0.
inline double elements_step(double x_rev, const double* delta_rev, double* pos_rev, std::size_t m,
                            const double* k_kN_per_rev, double* n_out) {
  double f = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    const double n = element_step(x_rev, delta_rev[i], pos_rev[i]);
    if (n_out) n_out[i] = n;
    if (k_kN_per_rev) f += k_kN_per_rev[i] * delta_rev[i] * n;
  }
  return f;
}

// Thresholds: even Delta_i = (i / M) Delta_max, or geometric Delta_M = Delta_max,
// Delta_{i-1} = ratio * Delta_i.
inline void thresholds(std::size_t m, double delta_max_rev, bool geometric, double ratio, double* out) {
  for (std::size_t i = 0; i < m; ++i) {
    if (geometric) {
      out[i] = delta_max_rev * std::pow(ratio, static_cast<double>(m - 1 - i));
    } else {
      out[i] = delta_max_rev * static_cast<double>(i + 1) / static_cast<double>(m);
    }
  }
}

}  // namespace bbw::model

// The names where they lived before model/ existed (bbw::calibration), so code written against them
// keeps compiling; new code says bbw::model.
namespace bbw::calibration {
using model::element_step;
using model::elements_step;
using model::thresholds;
}  // namespace bbw::calibration
