#include "bbw/brake/speed_estimator.hpp"

#include <algorithm>
#include <cmath>

namespace bbw::brake {

double SpeedEstimator::update(double dt_s, const std::array<double, 4>& w, double ax_m_s2, bool braking_hard,
                              double held_slip) {
  const double raw = radius_m_ * *std::max_element(w.begin(), w.end());
  // While braking hard the fastest wheel is held at about held_slip: the speed is at least what
  // it reads and about raw / (1 - held_slip). Up: towards the raw reading, fast (a wheel never
  // turns faster than the car rolls it). Down: towards the slip-corrected reading, slowly.
  const double corrected = braking_hard ? raw / (1.0 - std::clamp(held_slip, 0.0, 0.5)) : raw;
  if (!started_) {
    v_ = raw;
    prev_ref_ = raw;
    started_ = true;
    return v_;
  }
  v_ += dt_s * (ax_m_s2 - bias_);
  if (raw > v_) {
    v_ += std::min(1.0, p_.up_gain_per_s * dt_s) * (raw - v_);
  } else if (!braking_hard) {
    v_ += std::min(1.0, p_.rolling_gain_per_s * dt_s) * (raw - v_);
  } else if (corrected < v_) {
    v_ += std::min(1.0, p_.down_gain_per_s * dt_s) * (corrected - v_);
  }
  if (!braking_hard && raw > 1.0) {
    // Rolling freely: the wheels' own acceleration tells the IMU's bias - when it is one a car can
    // have: a wheel-speed sensor reads 0 until its first tooth edge, and that step is no
    // acceleration (it once taught a bias of -6 m/s^2 that overestimated every stop's speed).
    const double wheel_accel = (raw - prev_ref_) / dt_s;
    if (std::abs(wheel_accel) <= p_.bias_max_wheel_accel_m_s2)
      bias_ += std::min(1.0, p_.bias_gain_per_s * dt_s) * ((ax_m_s2 - wheel_accel) - bias_);
  }
  prev_ref_ = raw;
  v_ = std::max(0.0, v_);
  return v_;
}

}  // namespace bbw::brake
