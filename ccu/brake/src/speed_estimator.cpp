#include "bbw/brake/speed_estimator.hpp"

#include <algorithm>
#include <cmath>

namespace bbw::brake {

SpeedEstimator::SpeedEstimator(const SpeedEstimatorParams& p, double wheel_radius_m) : p_(p), radius_m_(wheel_radius_m) {}

double SpeedEstimator::update(double dt_s, const std::array<double, 4>& w, double ax_m_s2, bool braking_hard, double held_slip) {
  std::array<WheelBrakeStatus, 4> wheels{};
  for (WheelBrakeStatus& s : wheels) {
    s.controlled = braking_hard && held_slip > 0.0;
    s.pads_off_s = braking_hard ? 0.0 : 1e9;
  }
  return update(dt_s, w, ax_m_s2, braking_hard, held_slip, wheels);
}

double SpeedEstimator::update(double dt_s, const std::array<double, 4>& w, double ax_m_s2, bool braking_hard, double held_slip,
                              const std::array<WheelBrakeStatus, 4>& wheels) {
  std::array<double, 4> rim{};
  for (std::size_t i = 0; i < 4; ++i) rim[i] = radius_m_ * w[i];
  const std::size_t f = static_cast<std::size_t>(std::max_element(rim.begin(), rim.end()) - rim.begin());
  const double raw = rim[f];
  if (!started_) {
    v_ = raw;
    filt_ = rim;
    started_ = true;
  }
  // The wheels' filtered speeds and the IMU's integrated speed, with their history: over the
  // window a freely rolling wheel's speed changes as the IMU's does; one spinning up (released
  // from a slip) or diving into a slip does not.
  const double a = std::min(1.0, dt_s / p_.wheel_filter_s);
  for (std::size_t i = 0; i < 4; ++i) filt_[i] += a * (rim[i] - filt_[i]);
  imu_v_ += dt_s * (ax_m_s2 - bias_);
  hist_w_[head_] = filt_;
  hist_imu_[head_] = imu_v_;
  head_ = (head_ + 1) % kHistory;
  filled_ = std::min(filled_ + 1, kHistory);
  const std::size_t n = std::clamp<std::size_t>(static_cast<std::size_t>(std::lround(p_.reference_window_s / dt_s)), 1, kHistory - 1);
  const bool window = filled_ > n;
  const std::size_t old = (head_ + kHistory - 1 - n) % kHistory;
  const double span_s = static_cast<double>(n) * dt_s;
  const double wheel_accel = window ? (filt_[f] - hist_w_[old][f]) / span_s : 0.0;
  // The fastest wheel's speed less the IMU's integrated speed: flat over the whole window (within
  // reference_tolerance_m_s of its value now) when the wheel rolls freely - not only on average (a
  // wheel at the bottom of a slip dip, turning from braking to spinning up, matches the IMU on average).
  const double d_now = filt_[f] - imu_v_;
  double deviation = window ? 0.0 : 1e9;
  for (std::size_t k = 1; window && k <= n; ++k) {
    const std::size_t j = (head_ + kHistory - 1 - k) % kHistory;
    deviation = std::max(deviation, std::abs(hist_w_[j][f] - hist_imu_[j] - d_now));
  }
  // ... its slope: the bias error when it rolls freely (its acceleration less the IMU's less the bias).
  const double mismatch = window ? (d_now - (hist_w_[old][f] - hist_imu_[old])) / span_s : 0.0;
  // A reference: the fastest wheel, its pads off the disc for reference_release_s and spun up
  // (its speed follows the IMU's): it reads the car's speed.
  reference_ = window && raw > 1.0 && wheels[f].pads_off_s >= p_.reference_release_s && deviation <= p_.reference_tolerance_m_s &&
               std::abs(wheel_accel) <= p_.bias_max_wheel_accel_m_s2;
  if (reference_) ++reference_periods_;
  const bool free = !braking_hard || reference_;
  v_ += dt_s * (ax_m_s2 - bias_);
  if (raw > v_) {
    v_ += std::min(1.0, p_.up_gain_per_s * dt_s) * (raw - v_);  // no wheel turns faster than the car rolls it
  } else if (free) {
    v_ += std::min(1.0, p_.rolling_gain_per_s * dt_s) * (raw - v_);
  } else if (!wheels[f].controlled) {
    // Braked by the driver's torque, below the slip controllers' target: it reads at least
    // (1 - held_slip) of the speed. A wheel under slip control is held at a slip of this very
    // estimate: its speed says nothing about the car's, so the estimate integrates the IMU.
    const double corrected = raw / (1.0 - std::clamp(held_slip, 0.0, 0.5));
    if (corrected < v_) v_ += std::min(1.0, p_.down_gain_per_s * dt_s) * (corrected - v_);
  }
  // The IMU's bias, learned from a reference wheel only (before the brakes come on, and from a
  // released, spun-up wheel while braking): a sensor's first edge (0 -> v) or a wheel spinning up
  // is no acceleration of the car (the first once taught a bias of -6 m/s^2).
  if (reference_) bias_ -= std::min(1.0, p_.bias_gain_per_s * dt_s) * mismatch;  // mismatch = bias - true bias
  v_ = std::max(0.0, v_);
  return v_;
}

}  // namespace bbw::brake
