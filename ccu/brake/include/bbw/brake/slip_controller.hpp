// Continuous per-wheel slip control (ABS for an electromechanical brake): while the driver's
// torque would take the wheel past its target slip, a PI loop on the wheel-speed error holds
// it at the target with a continuously varying torque (no pressure cycling). The target is
// found online: the tyre's mu is estimated from the brake torque the CCU believes it applies
// (its clamp-force estimate) and the wheel's deceleration, and a square-wave dither on the
// target compares mu on either side (extremum seeking). Pure; the CCU period passed in.
#pragma once

#include "bbw/brake/params.hpp"

namespace bbw::brake {

struct WheelInputs {
  double wheel_rad_s = 0.0;        // sensor reading
  double ground_speed_m_s = 0.0;   // estimated speed of the wheel's centre over ground
  double request_Nm = 0.0;         // the driver's torque for this wheel (distribution applied)
  double applied_Nm = 0.0;         // the torque the CCU estimates the brake applies now
  double load_N = 0.0;             // estimated vertical load
};

struct WheelDecision {
  double torque_Nm = 0.0;
  double slip = 0.0;               // measured slip (positive braking)
  double target_slip = 0.0;
  double mu_estimate = 0.0;
  bool active = false;             // the slip controller limits the torque
};

class SlipController {
 public:
  // Nm_per_kN: the CCU's brake model (torque per kN of clamp force) for the caliper model.
  SlipController(const SlipControlParams& p, double wheel_radius_m, double wheel_inertia_kg_m2, double Nm_per_kN = 91.2);
  const WheelDecision& update(double dt_s, const WheelInputs& in);
  // The torque actually sent to the corner this period (after the yaw-moment limitation and the
  // clamp-force limits): the caliper model's input for the next period.
  void commanded(double torque_Nm) { sent_Nm_ = torque_Nm; }
  double model_torque_Nm() const { return model_kN_ * Nm_per_kN_; }  // the caliper model's force at the disc, as torque
  double model_gap() const { return gap_; }                         // 0: pads on the disc, 1: fully retracted
  unsigned long integral_holds() const { return held_; }          // periods the integral was held (caliper model)
  const WheelDecision& last() const { return d_; }
  double target_slip() const { return target_; }
  unsigned long jump_releases() const { return jumps_; }  // high-to-low mu jumps released

 private:
  void search(double dt_s, double slip);
  void caliper_step(double dt_s);
  SlipControlParams p_;
  double radius_m_, inertia_kg_m2_, Nm_per_kN_;
  // The caliper model: the torque sent last period, the force at the disc, the air gap (0 closed, 1 open).
  double sent_Nm_ = 0.0, model_kN_ = 0.0, gap_ = 1.0;
  unsigned long held_ = 0;
  double w_filt_ = 0.0, w_prev_ = 0.0, w_dot_ = 0.0;
  bool started_ = false;
  double integral_Nm_ = 0.0;
  double mu_ = 0.0;
  double target_;
  // Extremum seeking.
  double phase_s_ = 0.0;
  int side_ = 1;
  double sum_mu_ = 0.0;
  int count_ = 0;
  double mean_plus_ = 0.0, mean_minus_ = 0.0;
  bool have_plus_ = false, have_minus_ = false;
  unsigned long jumps_ = 0;
  WheelDecision d_;
};

}  // namespace bbw::brake
