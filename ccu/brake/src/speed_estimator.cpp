#include "bbw/brake/speed_estimator.hpp"

#include <algorithm>
#include <cmath>

namespace bbw::brake {

double SpeedEstimator::update(double dt_s, const std::array<double, 4>& w, double ax_m_s2, bool braking_hard) {
  const double ref = radius_m_ * *std::max_element(w.begin(), w.end());
  if (!started_) {
    v_ = ref;
    prev_ref_ = ref;
    started_ = true;
    return v_;
  }
  v_ += dt_s * (ax_m_s2 - bias_);
  const double err = ref - v_;
  double gain = p_.rolling_gain_per_s;
  if (err > 0.0) {
    gain = p_.up_gain_per_s;
  } else if (braking_hard) {
    gain = p_.down_gain_per_s;
  }
  v_ += std::min(1.0, gain * dt_s) * err;
  if (!braking_hard && ref > 1.0) {
    // Rolling freely: the wheels' own acceleration tells the IMU's bias.
    const double wheel_accel = (ref - prev_ref_) / dt_s;
    bias_ += std::min(1.0, p_.bias_gain_per_s * dt_s) * ((ax_m_s2 - wheel_accel) - bias_);
  }
  prev_ref_ = ref;
  v_ = std::max(0.0, v_);
  return v_;
}

}  // namespace bbw::brake
