// The vehicle's sensors, seeded: a toothed-wheel speed sensor per wheel (edge timing with a
// timer resolution and per-tooth pitch errors; the speed is one tooth pitch over the last edge
// interval) and an IMU (longitudinal and lateral acceleration, yaw rate; white noise plus a
// constant bias). Pure: time is an argument; no allocation per step.
#pragma once

#include <array>
#include <cstdint>
#include <random>

namespace bbw::vehicle {

struct WheelSpeedSensorParams {
  int teeth = 48;
  double timer_resolution_s = 1e-6;  // edge time stamps are quantised to this
  double pitch_error = 0.002;        // standard deviation of each tooth's angular pitch, relative
  double timeout_s = 0.2;            // no edge for this long: the reading is 0

  void validate() const;
};

class WheelSpeedSensor {
 public:
  WheelSpeedSensor(const WheelSpeedSensorParams& p, std::uint64_t seed);
  // Starts at angle_rad at time_s (no edge seen yet).
  void reset(double angle_rad, double time_s);
  // The wheel turned from the last angle to angle_rad by time_s (linear in between).
  void update(double angle_rad, double time_s);
  // The reading at time_s, rad/s.
  double speed_rad_s(double time_s) const;
  std::uint64_t edges() const { return edges_; }

 private:
  double edge_angle(std::int64_t n) const;
  WheelSpeedSensorParams p_;
  double pitch_rad_;
  std::array<double, 256> offset_rad_{};  // per-tooth edge offsets
  double last_angle_rad_ = 0.0;
  double last_time_s_ = 0.0;
  std::int64_t next_edge_ = 1;
  double edge_s_ = -1.0, prev_edge_s_ = -1.0;
  std::uint64_t edges_ = 0;
};

struct ImuParams {
  double accel_noise_m_s2 = 0.05;      // standard deviation per sample
  double accel_bias_m_s2 = 0.03;       // constant bias, x and y (signs from the seed)
  double yaw_rate_noise_rad_s = 0.002;
  double yaw_rate_bias_rad_s = 0.001;

  void validate() const;
};

struct ImuReading {
  double ax_m_s2 = 0.0;
  double ay_m_s2 = 0.0;
  double yaw_rate_rad_s = 0.0;
};

class Imu {
 public:
  Imu(const ImuParams& p, std::uint64_t seed);
  ImuReading read(double ax_m_s2, double ay_m_s2, double yaw_rate_rad_s);

 private:
  ImuParams p_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  double bias_ax_, bias_ay_, bias_r_;
};

}  // namespace bbw::vehicle
