#include "bbw/corner_unit/controller.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace bbw::corner_unit {
namespace {

constexpr double kTwoPi = 6.283185307179586;

void positive(const char* field, double v) {
  if (!(std::isfinite(v) && v > 0.0)) {
    std::ostringstream os;
    os << field << " = " << v << ": must be > 0";
    throw std::invalid_argument(os.str());
  }
}
void non_negative(const char* field, double v) {
  if (!(std::isfinite(v) && v >= 0.0)) {
    std::ostringstream os;
    os << field << " = " << v << ": must be >= 0";
    throw std::invalid_argument(os.str());
  }
}

}  // namespace

void ControllerParams::validate() const {
  positive("actuator.torque_per_A_Nm", actuator.torque_per_A_Nm);
  positive("actuator.Nm_per_kN", actuator.Nm_per_kN);
  non_negative("actuator.inertia_kg_m2", actuator.inertia_kg_m2);
  positive("current_limit_A", current_limit_A);
  positive("position_gain_per_s", position_gain_per_s);
  positive("speed_gain_A_per_rev_per_s", speed_gain_A_per_rev_per_s);
  non_negative("speed_integral_gain_A_per_rev", speed_integral_gain_A_per_rev);
  positive("max_speed_rev_per_s", max_speed_rev_per_s);
  positive("force_bandwidth_rad_per_s", force_bandwidth_rad_per_s);
  non_negative("force_integral_rad_per_s2", force_integral_rad_per_s2);
  non_negative("force_integral_max_speed_error_rev_per_s", force_integral_max_speed_error_rev_per_s);
  non_negative("force_home_margin_rev", force_home_margin_rev);
  positive("stiffness_at_zero_kN_per_rev", stiffness_at_zero_kN_per_rev);
  non_negative("stiffness_per_kN_per_rev", stiffness_per_kN_per_rev);
  non_negative("release_force_kN", release_force_kN);
  positive("stiffness_stride_rev", stiffness_stride_rev);
  positive("stiffness_stride_kN", stiffness_stride_kN);
  positive("stiffness_memory_rev", stiffness_memory_rev);
  non_negative("stiffness_reversal_rev", stiffness_reversal_rev);
  positive("stiffness_hold_rev", stiffness_hold_rev);
  non_negative("hold_test_current_A", hold_test_current_A);
  positive("hold_test_pulse_s", hold_test_pulse_s);
  positive("hold_test_period_s", hold_test_period_s);
  non_negative("hold_test_min_hold_s", hold_test_min_hold_s);
  non_negative("hold_test_min_force_kN", hold_test_min_force_kN);
  positive("hold_test_max_speed_rev_per_s", hold_test_max_speed_rev_per_s);
  positive("hold_test_max_error_kN", hold_test_max_error_kN);
  if (hold_test_current_A > 0.0 && 2.0 * hold_test_pulse_s >= hold_test_period_s)
    throw std::invalid_argument("hold_test_pulse_s must be shorter than half hold_test_period_s");
  if (frozen_resolver_samples < 0) throw std::invalid_argument("frozen_resolver_samples must be >= 0 (0: off)");
  if (!(std::isfinite(stiffness_max_ratio) && stiffness_max_ratio >= 1.0)) {
    std::ostringstream os;
    os << "stiffness_max_ratio = " << stiffness_max_ratio << ": must be >= 1";
    throw std::invalid_argument(os.str());
  }
  if (!std::isfinite(release_position_rev)) throw std::invalid_argument("release_position_rev must be finite");
}

const char* to_string(ForceFeedback f) {
  switch (f) {
    case ForceFeedback::LoadCell: return "load_cell";
    case ForceFeedback::Compensated: return "compensated";
    case ForceFeedback::Curve: return "curve";
    case ForceFeedback::True: return "true";
  }
  return "?";
}

double select_force(ForceFeedback f, const ForceSources& s) {
  switch (f) {
    case ForceFeedback::LoadCell: return s.load_cell_kN;
    case ForceFeedback::Compensated: return s.load_cell_kN - s.friction_estimate_kN;
    case ForceFeedback::Curve: return s.curve_estimate_kN;
    case ForceFeedback::True: return s.true_kN;
  }
  return s.load_cell_kN;
}

LocalController::LocalController(const ControllerParams& params) : p_(params) {
  p_.validate();
}

void LocalController::reset() { s_ = ControllerState{}; }

ControllerOutput LocalController::speed_loop(double v_ref, double a_ff, const ControllerInputs& in,
                                             double dt_s) {
  const double e = v_ref - in.speed_rev_per_s;
  double i_ff = p_.actuator.inertia_kg_m2 * kTwoPi * a_ff / p_.actuator.torque_per_A_Nm;
  if (p_.load_feedforward) {
    i_ff += std::max(in.load_force_kN, 0.0) * p_.actuator.Nm_per_kN / p_.actuator.torque_per_A_Nm;
  }
  const double unclipped = p_.speed_gain_A_per_rev_per_s * e + s_.speed_integral_A + i_ff;
  const double lim = p_.current_limit_A;
  const double cmd = std::clamp(unclipped, -lim, lim);
  const bool sat = cmd != unclipped;
  // Conditional integration: stop while clipped and the error would push further out.
  if (!sat || (unclipped > lim && e < 0.0) || (unclipped < -lim && e > 0.0)) {
    s_.speed_integral_A += p_.speed_integral_gain_A_per_rev * e * dt_s;
    s_.speed_integral_A = std::clamp(s_.speed_integral_A, -lim, lim);
  }
  return ControllerOutput{cmd, v_ref, sat};
}

bool LocalController::resolver_frozen(const ControllerInputs& in) {
  const bool same = in.position_rev == s_.last_position_rev && in.speed_rev_per_s == s_.last_speed_rev_per_s;
  s_.resolver_repeats = same ? s_.resolver_repeats + 1 : 0;
  s_.last_position_rev = in.position_rev;
  s_.last_speed_rev_per_s = in.speed_rev_per_s;
  s_.resolver_frozen = p_.frozen_resolver_samples > 0 && s_.resolver_repeats >= p_.frozen_resolver_samples;
  if (s_.resolver_frozen) {
    s_.speed_integral_A = 0.0;
    s_.force_integral_kN_s = 0.0;
    s_.stiffness.started = false;
  }
  return s_.resolver_frozen;
}

ControllerOutput LocalController::update_position(const PositionReference& ref, const ControllerInputs& in,
                                                  double dt_s) {
  if (!(dt_s > 0.0)) return ControllerOutput{};
  if (resolver_frozen(in)) return ControllerOutput{};
  const double unclipped = ref.speed_rev_per_s + p_.position_gain_per_s * (ref.position_rev - in.position_rev);
  const double v_ref = std::clamp(unclipped, -p_.max_speed_rev_per_s, p_.max_speed_rev_per_s);
  const double a_ff = v_ref == unclipped ? ref.accel_rev_per_s2 : 0.0;
  return speed_loop(v_ref, a_ff, in, dt_s);
}

void LocalController::update_stiffness(double model_kN_per_rev, const ControllerInputs& in) {
  StiffnessEstimate& e = s_.stiffness;
  if (!p_.stiffness_estimate) {
    e.stiffness_kN_per_rev = e.held_kN_per_rev = model_kN_per_rev;
    return;
  }
  const double prior_rev2 = p_.stiffness_stride_rev * p_.stiffness_stride_rev;
  if (!e.started) {
    e = StiffnessEstimate{};
    e.started = true;
    e.anchor_position_rev = in.position_rev;
    e.anchor_force_kN = in.force_feedback_kN;
  }
  const double dx = in.position_rev - e.anchor_position_rev;
  const double df = in.force_feedback_kN - e.anchor_force_kN;
  double forget_held = 1.0;
  if (std::abs(dx) >= p_.stiffness_stride_rev || std::abs(df) >= p_.stiffness_stride_kN) {
    const int dir = std::abs(dx) >= p_.stiffness_reversal_rev ? (dx > 0.0 ? 1 : -1) : 0;
    if (dir != 0 && e.direction != 0 && dir != e.direction) {
      e.sum_xx_rev2 = 0.0;  // a reversal: every friction element sticks again
      e.sum_xf_kN_rev = 0.0;
    }
    if (dir != 0) e.direction = dir;
    const double w = std::exp(-std::abs(dx) / p_.stiffness_memory_rev);
    e.sum_xx_rev2 = w * e.sum_xx_rev2 + dx * dx;
    e.sum_xf_kN_rev = w * e.sum_xf_kN_rev + dx * df;
    e.anchor_position_rev = in.position_rev;
    e.anchor_force_kN = in.force_feedback_kN;
    forget_held = std::exp(-std::abs(dx) / p_.stiffness_hold_rev);
  }
  const double seen = (e.sum_xf_kN_rev + model_kN_per_rev * prior_rev2) / (e.sum_xx_rev2 + prior_rev2);
  e.stiffness_kN_per_rev = std::clamp(seen, model_kN_per_rev, p_.stiffness_max_ratio * model_kN_per_rev);
  e.held_kN_per_rev = std::max(e.stiffness_kN_per_rev, forget_held * e.held_kN_per_rev);
}

ControllerOutput LocalController::update_force(double force_command_kN, const ControllerInputs& in,
                                               double dt_s, double force_rate_kN_per_s) {
  if (!(dt_s > 0.0)) return ControllerOutput{};
  if (force_command_kN <= p_.release_force_kN) {
    s_.hold_s = 0.0;
    s_.pulse_s = -1.0;
    s_.releasing = true;
    s_.force_integral_kN_s = 0.0;
    s_.stiffness.started = false;  // a new apply starts from the nominal slope
    return update_position(PositionReference{p_.release_position_rev, 0.0, 0.0}, in, dt_s);
  }
  s_.releasing = false;
  if (p_.feedback_switch_restart && in.feedback_switched) {
    s_.stiffness.started = false;
    s_.force_integral_kN_s = 0.0;
  }
  if (resolver_frozen(in)) {
    s_.hold_s = 0.0;
    s_.pulse_s = -1.0;
    return ControllerOutput{};
  }
  {
    ControllerOutput pulse;
    if (pulse_step(dt_s, pulse)) return pulse;
  }
  const double e = force_command_kN - in.force_feedback_kN;
  update_stiffness(p_.stiffness_at_zero_kN_per_rev + p_.stiffness_per_kN_per_rev * std::max(in.force_feedback_kN, 0.0),
                   in);
  const double unclipped =
      force_rate_kN_per_s / s_.stiffness.stiffness_kN_per_rev +
      (p_.force_bandwidth_rad_per_s * e + p_.force_integral_rad_per_s2 * s_.force_integral_kN_s) / s_.stiffness.held_kN_per_rev;
  double v_ref = std::clamp(unclipped, -p_.max_speed_rev_per_s, p_.max_speed_rev_per_s);
  // Behind the released home (by more than force_home_margin_rev: an apply from the home starts
  // with a few thousandths of a rev back) the force loop turns back at the position loop's rate: a loop on a
  // feedback that reads too much (a load cell biased high, a curve estimate below its fitted
  // range) no longer drives the actuator onto its retracted stop at full speed and winds its speed
  // integrator there (tuning seed 1408 run 344: 0.27 s at -40 A on the stop while 1.5-4 kN was
  // commanded, named actuator_tracking). Counts as clipped for the force integral.
  const double limit_rev = p_.release_position_rev - p_.force_home_margin_rev;
  if (p_.force_home_limit && in.position_rev < limit_rev) {
    v_ref = std::max(v_ref, std::min(p_.max_speed_rev_per_s, p_.position_gain_per_s * (limit_rev - in.position_rev)));
  }
  ControllerOutput out = speed_loop(v_ref, 0.0, in, dt_s);
  const bool clipped = v_ref != unclipped || out.saturated;
  const double push = unclipped - v_ref + (out.saturated ? out.current_command_A : 0.0);
  const bool following = !(p_.force_integral_max_speed_error_rev_per_s > 0.0) ||
                         std::abs(v_ref - in.speed_rev_per_s) <= p_.force_integral_max_speed_error_rev_per_s;
  if (following && (!clipped || (push > 0.0 && e < 0.0) || (push < 0.0 && e > 0.0))) {
    s_.force_integral_kN_s += e * dt_s;
  }
  out.saturated = clipped;
  hold_test(force_command_kN, e, in, dt_s, out);
  return out;
}

void LocalController::hold_test(double force_command_kN, double error_kN, const ControllerInputs& in, double dt_s,
                                ControllerOutput& out) {
  if (!(p_.hold_test_current_A > 0.0)) return;
  const bool holding = force_command_kN >= p_.hold_test_min_force_kN &&
                       std::abs(in.speed_rev_per_s) <= p_.hold_test_max_speed_rev_per_s &&
                       std::abs(error_kN) <= p_.hold_test_max_error_kN && !out.saturated;
  if (!holding) {
    s_.hold_s = 0.0;
    return;
  }
  s_.hold_s += dt_s;
  s_.since_test_s += dt_s;
  if (s_.hold_s >= p_.hold_test_min_hold_s && s_.since_test_s >= p_.hold_test_period_s) {
    // The pulse starts with the next sample, on top of this sample's loop current, which the
    // loops hold (integrators and all) until it is over.
    s_.pulse_s = 0.0;
    s_.since_test_s = 0.0;
    s_.pulse_base_A = out.current_command_A;
  }
}

bool LocalController::pulse_step(double dt_s, ControllerOutput& out) {
  if (s_.pulse_s < 0.0) return false;
  // Back first, then forth, each by the hold's own current and the test current more: the current
  // changes sign both ways, so a gear held against its flank (backlash) or a spindle held by its
  // friction still lets the rotor move.
  const double sign = s_.pulse_s < p_.hold_test_pulse_s - 1e-12 ? -1.0 : 1.0;
  const double amplitude_A = std::abs(s_.pulse_base_A) + p_.hold_test_current_A;
  out = ControllerOutput{};
  out.current_command_A =
      std::clamp(s_.pulse_base_A + sign * amplitude_A, -p_.current_limit_A, p_.current_limit_A);
  s_.pulse_s += dt_s;
  if (s_.pulse_s >= 2.0 * p_.hold_test_pulse_s - 1e-12) s_.pulse_s = -1.0;
  return true;
}

}  // namespace bbw::corner_unit
