// The vehicle's speed over ground from the four wheel speeds and the IMU's longitudinal
// acceleration: integrate the acceleration (less its learned bias), pull towards the fastest
// wheel (fast when it reads faster, slowly when the wheels are braked and slip, briskly while
// they roll freely). Pure; time step passed in.
#pragma once

#include <array>

#include "bbw/brake/params.hpp"

namespace bbw::brake {

class SpeedEstimator {
 public:
  explicit SpeedEstimator(const SpeedEstimatorParams& p, double wheel_radius_m) : p_(p), radius_m_(wheel_radius_m) {}
  // wheel_rad_s: the four sensor readings; ax_m_s2: IMU longitudinal acceleration; braking_hard:
  // some wheel is under slip control or strongly braked; held_slip: the slip the fastest wheel is
  // held at while braking hard (the slip controllers' smallest target; 0 when none is active):
  // the fastest wheel then reads (1 - held_slip) of the speed. Returns the estimate, m/s.
  double update(double dt_s, const std::array<double, 4>& wheel_rad_s, double ax_m_s2, bool braking_hard,
                double held_slip = 0.0);
  double speed_m_s() const { return v_; }
  double bias_m_s2() const { return bias_; }

 private:
  SpeedEstimatorParams p_;
  double radius_m_;
  double v_ = 0.0;
  double bias_ = 0.0;
  double prev_ref_ = 0.0;
  bool started_ = false;
};

}  // namespace bbw::brake
