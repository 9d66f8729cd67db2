// The characteristic curve: clamp force as a cubic in actuator position.
#pragma once

namespace bbw::calibration {

struct Curve {
  double a = 0.0;  // kN/rev^3
  double b = 0.0;  // kN/rev^2
  double c = 0.0;  // kN/rev
  double d = 0.0;  // kN

  double force_kN(double x_rev) const { return ((a * x_rev + b) * x_rev + c) * x_rev + d; }
};

}  // namespace bbw::calibration
