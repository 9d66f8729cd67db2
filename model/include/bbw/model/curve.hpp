// The characteristic curve: clamp force as a cubic in actuator position.
#pragma once

namespace bbw::model {

struct Curve {
  double a = 0.0;  // kN/rev^3
  double b = 0.0;  // kN/rev^2
  double c = 0.0;  // kN/rev
  double d = 0.0;  // kN

  double force_kN(double x_rev) const { return ((a * x_rev + b) * x_rev + c) * x_rev + d; }
};

}  // namespace bbw::model

// The names where they lived before model/ existed (bbw::calibration), so code written against them
// keeps compiling; new code says bbw::model.
namespace bbw::calibration {
using model::Curve;
}  // namespace bbw::calibration
