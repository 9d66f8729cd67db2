#include "bbw/vehicle/sensors.hpp"

#include <cmath>
#include <stdexcept>

namespace bbw::vehicle {

namespace {
constexpr double kTwoPi = 6.283185307179586;
}

void WheelSpeedSensorParams::validate() const {
  if (teeth < 4 || teeth > 256) throw std::invalid_argument("wheel_speed.teeth must be in [4, 256]");
  if (!(timer_resolution_s > 0.0 && timer_resolution_s <= 1e-3)) {
    throw std::invalid_argument("wheel_speed.timer_resolution_s must be in (0, 0.001]");
  }
  if (!(pitch_error >= 0.0 && pitch_error <= 0.05)) throw std::invalid_argument("wheel_speed.pitch_error must be in [0, 0.05]");
  if (!(timeout_s > 0.0)) throw std::invalid_argument("wheel_speed.timeout_s must be > 0");
}

WheelSpeedSensor::WheelSpeedSensor(const WheelSpeedSensorParams& p, std::uint64_t seed) : p_(p) {
  p_.validate();
  pitch_rad_ = kTwoPi / p_.teeth;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  // Cumulative pitch errors around the wheel, closed so the teeth still make one turn.
  double sum = 0.0;
  for (int i = 0; i < p_.teeth; ++i) {
    sum += p_.pitch_error * pitch_rad_ * normal(rng);
    offset_rad_[static_cast<std::size_t>(i)] = sum;
  }
  const double drift = sum / p_.teeth;
  for (int i = 0; i < p_.teeth; ++i) offset_rad_[static_cast<std::size_t>(i)] -= drift * (i + 1);
}

double WheelSpeedSensor::edge_angle(std::int64_t n) const {
  const std::int64_t t = ((n % p_.teeth) + p_.teeth) % p_.teeth;
  return static_cast<double>(n) * pitch_rad_ + offset_rad_[static_cast<std::size_t>(t)];
}

void WheelSpeedSensor::reset(double angle_rad, double time_s) {
  last_angle_rad_ = angle_rad;
  last_time_s_ = time_s;
  next_edge_ = static_cast<std::int64_t>(std::floor(angle_rad / pitch_rad_)) + 1;
  while (edge_angle(next_edge_) <= angle_rad) ++next_edge_;
  edge_s_ = prev_edge_s_ = -1.0;
}

void WheelSpeedSensor::update(double angle_rad, double time_s) {
  const double da = angle_rad - last_angle_rad_;
  while (da > 0.0 && edge_angle(next_edge_) <= angle_rad) {
    const double frac = (edge_angle(next_edge_) - last_angle_rad_) / da;
    const double t = last_time_s_ + frac * (time_s - last_time_s_);
    prev_edge_s_ = edge_s_;
    edge_s_ = std::floor(t / p_.timer_resolution_s) * p_.timer_resolution_s;
    ++next_edge_;
    ++edges_;
  }
  last_angle_rad_ = angle_rad;
  last_time_s_ = time_s;
}

double WheelSpeedSensor::speed_rad_s(double time_s) const {
  if (prev_edge_s_ < 0.0 || edge_s_ <= prev_edge_s_) return 0.0;
  const double since = time_s - edge_s_;
  if (since > p_.timeout_s) return 0.0;
  const double interval = edge_s_ - prev_edge_s_;
  // A wheel that slows: no edge for longer than the last interval bounds the speed from above.
  return pitch_rad_ / std::max(interval, since);
}

void ImuParams::validate() const {
  if (!(accel_noise_m_s2 >= 0.0) || !(yaw_rate_noise_rad_s >= 0.0) || !std::isfinite(accel_bias_m_s2) ||
      !std::isfinite(yaw_rate_bias_rad_s)) {
    throw std::invalid_argument("imu: noise must be >= 0 and biases finite");
  }
}

Imu::Imu(const ImuParams& p, std::uint64_t seed) : p_(p), rng_(seed) {
  p_.validate();
  std::uniform_int_distribution<int> sign(0, 1);
  bias_ax_ = p_.accel_bias_m_s2 * (sign(rng_) ? 1.0 : -1.0);
  bias_ay_ = p_.accel_bias_m_s2 * (sign(rng_) ? 1.0 : -1.0);
  bias_r_ = p_.yaw_rate_bias_rad_s * (sign(rng_) ? 1.0 : -1.0);
}

ImuReading Imu::read(double ax_m_s2, double ay_m_s2, double yaw_rate_rad_s) {
  ImuReading r;
  r.ax_m_s2 = ax_m_s2 + bias_ax_ + p_.accel_noise_m_s2 * normal_(rng_);
  r.ay_m_s2 = ay_m_s2 + bias_ay_ + p_.accel_noise_m_s2 * normal_(rng_);
  r.yaw_rate_rad_s = yaw_rate_rad_s + bias_r_ + p_.yaw_rate_noise_rad_s * normal_(rng_);
  return r;
}

}  // namespace bbw::vehicle
