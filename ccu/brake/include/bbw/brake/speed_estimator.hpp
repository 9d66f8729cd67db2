// The vehicle's speed over ground from the four wheel speeds and the IMU's longitudinal
// acceleration: integrate the acceleration (less its learned bias), pull up fast to the fastest
// wheel (no wheel turns faster than the car rolls it), and down only towards a wheel that says
// something about the car's speed: one that rolls freely. A wheel under slip control says nothing
// (its controller holds it at a slip of the estimate itself: pulling the estimate towards it let
// the estimate fall 1-3 m/s below the car while four ice wheels slipped together, docs/vehicle.md).
// Pure; time step passed in.
#pragma once

#include <array>
#include <cstddef>

#include "bbw/brake/params.hpp"

namespace bbw::brake {

// What the CCU knows of a wheel's brake.
struct WheelBrakeStatus {
  bool controlled = false;  // its slip controller limits its torque (it holds a slip of the estimate)
  // How long its pads have been off the disc: its command at most free_rolling_torque_Nm and (with
  // the CCU's caliper model) the model's force at 0 and its air gap open.
  double pads_off_s = 0.0;
};

class SpeedEstimator {
 public:
  explicit SpeedEstimator(const SpeedEstimatorParams& p, double wheel_radius_m);
  // wheel_rad_s: the four sensor readings; ax_m_s2: IMU longitudinal acceleration; braking_hard:
  // some wheel is under slip control or the driver brakes hard; held_slip: the slip controllers'
  // smallest target (0 when none is active): a braked fastest wheel that is not under slip
  // control reads at least (1 - held_slip) of the speed; wheels: each wheel's brake. Returns the
  // estimate, m/s.
  double update(double dt_s, const std::array<double, 4>& wheel_rad_s, double ax_m_s2, bool braking_hard, double held_slip,
                const std::array<WheelBrakeStatus, 4>& wheels);
  // Every wheel under slip control while braking hard with a held slip, none released; every
  // wheel's pads off while not braking hard.
  double update(double dt_s, const std::array<double, 4>& wheel_rad_s, double ax_m_s2, bool braking_hard,
                double held_slip = 0.0);
  double speed_m_s() const { return v_; }
  double bias_m_s2() const { return bias_; }
  // The fastest wheel was a reference this period: released and spun up (its speed changed over
  // reference_window_s as the IMU's integrated acceleration did).
  bool reference() const { return reference_; }
  unsigned long reference_periods() const { return reference_periods_; }

 private:
  static constexpr std::size_t kHistory = 64;
  SpeedEstimatorParams p_;
  double radius_m_;
  double v_ = 0.0;
  double bias_ = 0.0;
  bool started_ = false;
  bool reference_ = false;
  unsigned long reference_periods_ = 0;
  // Filtered rim speeds and the IMU's integrated speed (ax less the bias), with their history
  // over the reference window (a ring buffer).
  std::array<double, 4> filt_{};
  double imu_v_ = 0.0;
  std::array<std::array<double, 4>, kHistory> hist_w_{};
  std::array<double, kHistory> hist_imu_{};
  std::size_t head_ = 0, filled_ = 0;
};

}  // namespace bbw::brake
