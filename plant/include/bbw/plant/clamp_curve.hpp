// The true characteristic curve: clamp force versus actuator position, moved by temperature
// and pad wear. Pure function of its arguments; see ClampCurveParams for the formula.
#pragma once

#include "bbw/plant/params.hpp"

namespace bbw::plant {

class ClampCurve {
 public:
  explicit ClampCurve(const ClampCurveParams& params);  // throws std::invalid_argument

  double contact_rev(double temperature_C, double wear_rev) const;
  double stiffness_scale(double temperature_C) const;
  double force_kN(double x_rev, double temperature_C, double wear_rev) const;
  // dF/dx, kN per rev (analytic).
  double slope_kN_per_rev(double x_rev, double temperature_C, double wear_rev) const;

  const ClampCurveParams& params() const { return p_; }

 private:
  ClampCurveParams p_;
};

}  // namespace bbw::plant
