// The calibrator's friction model replayed elsewhere (a corner's friction-compensated load-cell
// feedback, docs/distributed.md): Maxwell-slip elements with the published thresholds and
// stiffnesses, plus the optional effect terms (effect_terms.hpp: backlash play, load-dependent
// scaling along the published curve, viscous term, thermal offset), with its own element and play
// states. The same arithmetic as Calibrator::update's friction estimate (tested against it).
// Allocates only in reset().
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "bbw/model/curve.hpp"
#include "bbw/model/effect_terms.hpp"
#include "bbw/model/maxwell_slip.hpp"

namespace bbw::model {

struct FrictionModel {
  std::vector<double> delta_rev;             // thresholds Delta_i
  std::vector<double> stiffness_kN_per_rev;  // K_i
  double viscous_kN_per_rev_per_s = 0.0;     // c_v (0 = off)
  double load_gain = 0.0;                    // g (0 = off)
  double load_reference_kN = 40.0;
  double backlash_width_rev = 0.0;           // 0 = off
  double load_cell_offset_kN_per_C = 0.0;    // thermal zero drift k (0 = off)
  double load_cell_offset_reference_C = 40.0;
  Curve curve;                               // F(x), for the load-dependent scaling
};

class FrictionTracker {
 public:
  // States start at x_rev (every element and the spindle at rest there).
  void reset(std::size_t elements, double x_rev) {
    pos_rev_.assign(elements, x_rev);
    spindle_rev_ = x_rev;
    started_ = true;
  }
  bool started() const { return started_; }
  // Friction (kN) the load cell holds at resolver position x and speed v; the model's sizes
  // must match reset()'s.
  double step(const FrictionModel& m, double x_rev, double speed_rev_per_s) {
    const double x = BacklashTerm::on(m.backlash_width_rev)
                         ? BacklashTerm::spindle_rev(spindle_rev_, x_rev, m.backlash_width_rev)
                         : x_rev;
    double f = elements_step(x, m.delta_rev.data(), pos_rev_.data(), pos_rev_.size(), m.stiffness_kN_per_rev.data(),
                             nullptr);
    if (LoadFrictionTerm::on(m.load_gain)) {
      f *= LoadFrictionTerm::scale(m.load_gain, m.load_reference_kN, m.curve.force_kN(x));
    }
    return f + ViscousTerm::friction_kN(m.viscous_kN_per_rev_per_s, speed_rev_per_s);
  }
  // What the load cell reads beyond the clamp force at temperature T: the friction above plus
  // the thermal zero offset, as the calibrator removes it (a non-finite T: the last finite one;
  // none yet: no offset).
  double step_load_cell_excess(const FrictionModel& m, double x_rev, double speed_rev_per_s, double temperature_C) {
    const double f = step(m, x_rev, speed_rev_per_s);
    if (std::isfinite(temperature_C)) {
      temperature_C_ = temperature_C;
      have_temperature_ = true;
    }
    if (!LoadCellOffsetTerm::on(m.load_cell_offset_kN_per_C) || !have_temperature_) return f;
    return f + LoadCellOffsetTerm::offset_kN(m.load_cell_offset_kN_per_C, m.load_cell_offset_reference_C, temperature_C_);
  }

 private:
  std::vector<double> pos_rev_;
  double spindle_rev_ = 0.0;
  double temperature_C_ = 0.0;
  bool have_temperature_ = false;
  bool started_ = false;
};

}  // namespace bbw::model

// The names where they lived before model/ existed (bbw::calibration), so code written against them
// keeps compiling; new code says bbw::model.
namespace bbw::calibration {
using model::FrictionModel;
using model::FrictionTracker;
}  // namespace bbw::calibration
