#include "bbw/brake/slip_controller.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bbw::brake {

SlipController::SlipController(const SlipControlParams& p, double wheel_radius_m, double wheel_inertia_kg_m2, double Nm_per_kN)
    : p_(p), radius_m_(wheel_radius_m), inertia_kg_m2_(wheel_inertia_kg_m2), Nm_per_kN_(Nm_per_kN), target_(p.target_slip) {
  if (!(wheel_radius_m > 0.0) || !(wheel_inertia_kg_m2 > 0.0) || !(Nm_per_kN > 0.0))
    throw std::invalid_argument("SlipController: radius, inertia and Nm_per_kN must be > 0");
}

void SlipController::caliper_step(double dt_s) {
  const double cmd_kN = std::max(0.0, sent_Nm_) / Nm_per_kN_;
  const bool apply = cmd_kN > p_.caliper_release_kN;
  if (apply && gap_ > 0.0) {
    gap_ = std::max(0.0, gap_ - dt_s / p_.caliper_gap_s);  // closing the air gap: nothing brakes yet
  } else {
    const double target = apply ? cmd_kN : 0.0;
    // The force loop's lag, at most the motor's rate.
    model_kN_ += std::clamp((target - model_kN_) * std::min(1.0, dt_s / p_.caliper_lag_s), -p_.caliper_rate_kN_s * dt_s,
                            p_.caliper_rate_kN_s * dt_s);
    if (!apply && model_kN_ <= p_.caliper_release_kN) {
      model_kN_ = 0.0;  // the pads leave the disc and the air gap opens
      gap_ = std::min(1.0, gap_ + dt_s / p_.caliper_retract_s);
    }
  }
}

void SlipController::search(double dt_s, double slip) {
  phase_s_ += dt_s;
  if (phase_s_ > p_.dither_settle_s && std::abs(slip - (target_ + side_ * p_.dither_slip)) < 0.05) {
    sum_mu_ += mu_;
    ++count_;
  }
  if (phase_s_ < p_.dither_half_period_s) return;
  if (count_ > 0) {
    (side_ > 0 ? mean_plus_ : mean_minus_) = sum_mu_ / count_;
    (side_ > 0 ? have_plus_ : have_minus_) = true;
  }
  if (have_plus_ && have_minus_ && side_ < 0) {
    const double diff = mean_plus_ - mean_minus_;
    if (diff > p_.search_threshold_mu) target_ += p_.search_step;
    if (diff < -p_.search_threshold_mu) target_ -= p_.search_step;
    target_ = std::clamp(target_, p_.min_target_slip, p_.max_target_slip);
    have_plus_ = have_minus_ = false;
  }
  side_ = -side_;
  phase_s_ = 0.0;
  sum_mu_ = 0.0;
  count_ = 0;
}

const WheelDecision& SlipController::update(double dt_s, const WheelInputs& in) {
  const double a = std::min(1.0, dt_s / std::max(dt_s, 0.005));
  if (!started_) {
    w_filt_ = w_prev_ = in.wheel_rad_s;
    started_ = true;
  }
  w_filt_ += a * (in.wheel_rad_s - w_filt_);
  if (p_.caliper_model) caliper_step(dt_s);
  const double w_dot_raw = (w_filt_ - w_prev_) / dt_s;
  w_prev_ = w_filt_;
  const double b = std::min(1.0, dt_s / p_.mu_filter_s);
  w_dot_ += b * (w_dot_raw - w_dot_);
  const double v = in.ground_speed_m_s;
  d_.slip = v > 0.5 ? std::clamp(1.0 - radius_m_ * w_filt_ / v, -1.0, 1.0) : 0.0;
  // Tyre mu from the wheel's torque balance: R Fx = T_brake + I dw/dt (braking Fx > 0 here).
  // Both terms with the same lag (one mu filter): the inertia term from the period's own
  // deceleration, not from w_dot_ (already filtered once - filtered twice it lagged the brake
  // torque, and on ice, where it is as large as the tyre's torque, the estimate fell as the slip
  // rose and the target search ran to its floor; docs/vehicle.md, issue 15 ninth part).
  if (in.load_N > 0.0) {
    const double mu_raw = (in.applied_Nm + inertia_kg_m2_ * w_dot_raw) / (radius_m_ * in.load_N);
    mu_ += b * (mu_raw - mu_);
  }
  d_.mu_estimate = mu_;
  const double request = std::max(0.0, in.request_Nm);
  if (v < p_.min_speed_m_s || request <= 0.0) {
    d_.active = false;
    integral_Nm_ = request;
    d_.torque_Nm = request;
    d_.target_slip = target_;
    return d_;
  }
  const double target = target_ + (d_.active ? side_ * p_.dither_slip : 0.0);
  d_.target_slip = target;
  const double w_target = (1.0 - target) * v / radius_m_;
  const double err = w_filt_ - w_target;  // > 0: the wheel turns faster than the target: brake more
  if (!d_.active) {
    const bool deep = -w_dot_ * radius_m_ > p_.activation_wheel_decel_m_s2;
    if (d_.slip > target_ - p_.activation_margin || deep) {
      d_.active = true;
      // Bumpless: start from the torque the brake applies now, less what the wheel's
      // deceleration says is too much.
      integral_Nm_ = std::clamp(in.applied_Nm + inertia_kg_m2_ * w_dot_, 0.0, request);
    } else {
      integral_Nm_ = request;
      d_.torque_Nm = request;
      return d_;
    }
  }
  // High-to-low mu jump: the wheel falls away faster than any braking on the old surface could
  // make it; drop the integral at once to what the tyre carries now instead of integrating down.
  const double rim_decel = -w_dot_raw * radius_m_;
  const bool hard = p_.jump_hard_decel_m_s2 > 0.0 && rim_decel > p_.jump_hard_decel_m_s2;
  const bool falling = rim_decel > p_.jump_wheel_decel_m_s2 && d_.slip > target + p_.jump_slip_margin;
  if (hard) {
    // Falling faster than any tyre on the old surface allows: the caliper's release (about
    // 110 kN/s) is what sets the lock (docs/vehicle.md, "What is left" 3), so release fully.
    integral_Nm_ = 0.0;
    ++jumps_;
  } else if (falling) {
    const double tyre_Nm = std::max(0.0, in.applied_Nm + inertia_kg_m2_ * w_dot_raw);
    integral_Nm_ = std::min(integral_Nm_, p_.jump_release_factor * tyre_Nm);
    ++jumps_;
  }
  // The caliper model says the command has not reached the disc yet: while the pads close the
  // air gap nothing brakes, so a wheel spinning up is no reason to integrate the command up
  // (that wound it up to several times what an ice tyre carries before the pads touched); while
  // the force on the disc is still above the command the release is on its way, so a wheel
  // still slowing is no reason to integrate it down. The proportional part acts throughout.
  const bool closing = p_.caliper_model && gap_ > 0.0 && sent_Nm_ / Nm_per_kN_ > p_.caliper_release_kN;
  const bool releasing = p_.caliper_model && model_kN_ * Nm_per_kN_ > std::max(0.0, sent_Nm_) + p_.release_freeze_margin_Nm;
  if (closing && err > 0.0) ++held_;
  else if (releasing && err < 0.0) ++held_;
  else integral_Nm_ = std::clamp(integral_Nm_ + p_.ki_Nm_per_rad * err * dt_s, 0.0, request);
  const double torque = std::clamp(integral_Nm_ + p_.kp_Nm_per_rad_s * err, 0.0, request);
  d_.torque_Nm = torque;
  // The driver asks for less than the wheel can carry: hand back.
  if (integral_Nm_ >= request && err > 0.0) d_.active = false;
  if (d_.active) search(dt_s, d_.slip);
  return d_;
}

}  // namespace bbw::brake
