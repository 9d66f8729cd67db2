// The play (backlash) operator: a spindle dragged along by the resolver position within half the
// play. Pure arithmetic; shared by the plant, the calibrator's backlash term and the corners.
#pragma once

namespace bbw::model {

// Backlash: one step of the play operator. `spindle_rev` (the state) is dragged along so that it
// stays within half the play of the resolver position; returns it.
inline double play_step(double& spindle_rev, double x_rev, double width_rev) {
  const double half = 0.5 * width_rev;
  if (spindle_rev < x_rev - half) spindle_rev = x_rev - half;
  if (spindle_rev > x_rev + half) spindle_rev = x_rev + half;
  return spindle_rev;
}

}  // namespace bbw::model

// The names where they lived before model/ existed (bbw::calibration), so code written against them
// keeps compiling; new code says bbw::model.
namespace bbw::calibration {
using model::play_step;
}  // namespace bbw::calibration
