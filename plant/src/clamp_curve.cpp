#include "bbw/plant/clamp_curve.hpp"

#include <cmath>

namespace bbw::plant {
namespace {

// Smooth max(d, 0) with width eps, and its derivative (a logistic).
double soft_plus(double d, double eps) {
  const double z = d / eps;
  if (z > 30.0) return d;
  return eps * std::log1p(std::exp(z));
}
double soft_plus_slope(double d, double eps) {
  const double z = d / eps;
  if (z > 30.0) return 1.0;
  if (z < -30.0) return 0.0;
  return 1.0 / (1.0 + std::exp(-z));
}

}  // namespace

ClampCurve::ClampCurve(const ClampCurveParams& params) : p_(params) {
  PlantParams check;
  check.curve = params;
  check.validate();
}

double ClampCurve::contact_rev(double temperature_C, double wear_rev) const {
  return p_.contact_rev + p_.contact_shift_rev_per_C * (temperature_C - p_.reference_temperature_C) +
         wear_rev;
}

double ClampCurve::stiffness_scale(double temperature_C) const {
  return 1.0 + p_.stiffness_change_per_C * (temperature_C - p_.reference_temperature_C);
}

double ClampCurve::force_kN(double x_rev, double temperature_C, double wear_rev) const {
  const double d = soft_plus(x_rev - contact_rev(temperature_C, wear_rev), p_.smoothing_rev);
  return stiffness_scale(temperature_C) *
         (p_.exp_coefficient_kN * std::expm1(d / p_.exp_length_rev) + p_.linear_kN_per_rev * d);
}

double ClampCurve::slope_kN_per_rev(double x_rev, double temperature_C, double wear_rev) const {
  const double delta = x_rev - contact_rev(temperature_C, wear_rev);
  const double d = soft_plus(delta, p_.smoothing_rev);
  const double dd = soft_plus_slope(delta, p_.smoothing_rev);
  return stiffness_scale(temperature_C) *
         (p_.exp_coefficient_kN / p_.exp_length_rev * std::exp(d / p_.exp_length_rev) +
          p_.linear_kN_per_rev) *
         dd;
}

}  // namespace bbw::plant
