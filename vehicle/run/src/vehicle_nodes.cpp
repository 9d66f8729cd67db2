#include "bbw/vehicle_run/vehicle_nodes.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "bbw/scenario/scenario.hpp"

namespace bbw::vehicle_run {

namespace {
constexpr double kLockSpeed_m_s = 15.0 / 3.6;
}

VehicleNode::VehicleNode(const VehicleScenario& s, int exchange_every_samples)
    : scenario_(s),
      every_(exchange_every_samples),
      dt_s_(s.corners.scenario.plant_dt_s),
      vehicle_(s.vehicle.vehicle, s.road),
      imu_(s.vehicle.imu, scenario::corner_seed(s.seed, 101)),
      pedal_profile_(s.vehicle.pedal, s.pedal, 0) {
  if (every_ < 1 || every_ > 64) throw std::invalid_argument("exchange_every_samples must be in [1, 64]");
  vehicle_.reset(s.initial_speed_m_s, s.disc_C, s.caliper_C);
  for (std::size_t w = 0; w < 4; ++w) {
    wheel_sensors_.emplace_back(s.vehicle.wheel_speed, scenario::corner_seed(s.seed, 110 + w));
    wheel_sensors_.back().reset(0.0, 0.0);
  }
  if (s.driver) driver_.emplace(s.driver_params, s.vehicle.vehicle.chassis.wheelbase_m());
  truth_.reserve(static_cast<std::size_t>(std::ceil(s.corners.scenario.duration_s / s.corners.scenario.ccu_period_s)) + 2);
}

void VehicleNode::on_block(std::size_t slot, const msg::MeasurementBlock& block) {
  for (const msg::MeasurementSample& m : block.samples()) {
    if (received_[slot] < force_[slot].size()) force_[slot][received_[slot]++] = m.force_true_kN();
  }
}

const msg::VehicleSensors& VehicleNode::simulate_period(std::uint64_t k, std::size_t n) {
  n = std::min<std::size_t>(n, 64);
  for (std::size_t w = 0; w < 4; ++w) {
    if (received_[w] > 0) last_force_kN_[w] = force_[w][received_[w] - 1];
    if (received_[w] == 0 && lost_[w]) last_force_kN_[w] = 0.0;  // a dead e-caliper releases
    // Missing samples (a silent or lost corner) hold the last force.
    for (std::size_t j = received_[w]; j < n; ++j) force_[w][j] = last_force_kN_[w];
    received_[w] = 0;
  }
  double ax = 0.0, ay = 0.0, r = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    const std::uint64_t global = k * n + j;
    for (std::size_t w = 0; w < 4; ++w) {
      if (every_ == 1 || global % static_cast<std::uint64_t>(every_) == 0) in_.clamp_force_kN[w] = force_[w][j];
    }
    const vehicle::VehicleState& st = vehicle_.state();
    const bool cruising = st.time_s < scenario_.cruise_until_s;
    if (scenario_.cruise_until_s > 0.0) {
      const double t = cruising ? std::max(0.0, scenario_.cruise_gain_Nm_per_m_s * (scenario_.initial_speed_m_s - vehicle_.speed_m_s())) : 0.0;
      in_.drive_torque_Nm[2] = in_.drive_torque_Nm[3] = t;
    }
    if (driver_) in_.steer_rad = driver_->steer(dt_s_, st.x_m, st.y_m, st.yaw_rad, vehicle_.speed_m_s(), st.yaw_rate_rad_s);
    vehicle_.step(dt_s_, in_);
    const vehicle::VehicleState& s = vehicle_.state();
    for (std::size_t w = 0; w < 4; ++w) wheel_sensors_[w].update(s.wheels[w].angle_rad, s.time_s);
    const vehicle::ImuReading imu = imu_.read(s.ax_m_s2, s.ay_m_s2, s.yaw_rate_rad_s);
    ax += imu.ax_m_s2 / static_cast<double>(n);
    ay += imu.ay_m_s2 / static_cast<double>(n);
    r += imu.yaw_rate_rad_s / static_cast<double>(n);
    const double v = vehicle_.speed_m_s();
    if (onset_s_ < 0.0 && s.time_s >= scenario_.cruise_until_s && pedal_profile_.travel_fraction(s.time_s) > 0.0) {
      onset_s_ = s.time_s;
      onset_speed_m_s_ = v;
      onset_path_m_ = s.path_m;
    }
    for (std::size_t w = 0; w < 4; ++w) {
      const double ws = s.wheels[w].spin_rad_s * scenario_.vehicle.vehicle.chassis.wheel_radius_m;
      if (v > kLockSpeed_m_s && ws < 0.5 * v) {
        lock_s_[w] += dt_s_;
        current_lock_s_[w] += dt_s_;
        longest_lock_s_[w] = std::max(longest_lock_s_[w], current_lock_s_[w]);
      } else {
        current_lock_s_[w] = 0.0;
      }
    }
    if (s.stopped && stop_time_s_ < 0.0) stop_time_s_ = s.time_s;
  }
  const vehicle::VehicleState& s = vehicle_.state();
  const double t_end = s.time_s;
  sensors_.step(k);
  sensors_.time_s(t_end);
  for (std::size_t w = 0; w < 4; ++w) {
    sensors_.wheel_speed_rad_s()[w] = wheel_sensors_[w].speed_rad_s(t_end);
    sensors_.caliper_temperature_C()[w] = s.wheels[w].caliper_C;
  }
  sensors_.ax_m_s2(ax);
  sensors_.ay_m_s2(ay);
  sensors_.yaw_rate_rad_s(r);
  // The steering-angle sensor: 0.1 deg at the hand wheel (ratio 15) as road-wheel resolution.
  constexpr double kSteerResolution_rad = 0.1 / 15.0 * M_PI / 180.0;
  sensors_.steering_angle_rad(std::round(in_.steer_rad / kSteerResolution_rad) * kSteerResolution_rad);
  sensors_.speed_true_m_s(vehicle_.speed_m_s());
  sensors_.x_true_m(s.x_m);
  sensors_.y_true_m(s.y_m);
  sensors_.path_true_m(s.path_m);
  sensors_.stopped(s.stopped);
  TruthRow t;
  t.time_s = t_end;
  t.speed_m_s = vehicle_.speed_m_s();
  t.x_m = s.x_m;
  t.y_m = s.y_m;
  t.yaw_rad = s.yaw_rad;
  t.yaw_rate_rad_s = s.yaw_rate_rad_s;
  t.ax_m_s2 = s.ax_m_s2;
  t.path_m = s.path_m;
  t.steer_rad = in_.steer_rad;
  t.stopped = s.stopped;
  for (std::size_t w = 0; w < 4; ++w) {
    const auto& o = vehicle_.wheels()[w];
    t.wheel_speed_m_s[w] = s.wheels[w].spin_rad_s * scenario_.vehicle.vehicle.chassis.wheel_radius_m;
    t.slip[w] = -o.slip;
    t.mu_used[w] = o.mu_used;
    t.surface_mu_scale[w] = o.surface_mu_scale;
    t.clamp_true_kN[w] = force_[w][n > 0 ? n - 1 : 0];
    t.brake_torque_Nm[w] = o.brake_torque_Nm;
    t.disc_C[w] = s.wheels[w].disc_C;
    t.caliper_C[w] = s.wheels[w].caliper_C;
    t.braking = t.braking || o.brake_torque_Nm > 0.0;
  }
  truth_.push_back(t);
  return sensors_;
}

PedalNode::PedalNode(const VehicleScenario& s) : pedal_(s.vehicle.pedal, s.pedal, scenario::corner_seed(s.seed, 100)) {}

const msg::PedalSample& PedalNode::sample(std::uint64_t k, double t_end_s) {
  const vehicle::PedalReading r = pedal_.read(t_end_s);
  sample_.step(k);
  sample_.time_s(t_end_s);
  sample_.travel_mm(r.travel_mm);
  sample_.force_N(r.force_N);
  return sample_;
}

BrakeFunctions::BrakeFunctions(const brake::BrakeControlParams& params, double period_s, const vehicle::VehicleState& start)
    : brake_(params), period_s_(period_s) {
  // Before the first period the wheels roll at the start speed.
  for (std::size_t w = 0; w < 4; ++w) meas_.wheel_rad_s[w] = start.wheels[w].spin_rad_s;
}

void BrakeFunctions::on_vehicle(const msg::VehicleSensors& s) {
  for (std::size_t w = 0; w < 4; ++w) meas_.wheel_rad_s[w] = s.wheel_speed_rad_s()[w];
  meas_.ax_m_s2 = s.ax_m_s2();
  meas_.ay_m_s2 = s.ay_m_s2();
  meas_.yaw_rate_rad_s = s.yaw_rate_rad_s();
  meas_.steer_rad = s.steering_angle_rad();
}

void BrakeFunctions::on_pedal(const msg::PedalSample& p) {
  meas_.pedal_travel_mm = p.travel_mm();
  meas_.pedal_force_N = p.force_N();
}

const brake::BrakeOutput& BrakeFunctions::plan(node::CcuNode& ccu) {
  for (std::size_t slot = 0; slot < 4; ++slot) {
    const faults::CornerView& v = ccu.core().supervisor(slot).view();
    const double est = v.estimate_valid() && std::isfinite(v.force_estimate_kN) ? v.force_estimate_kN : command_kN_[slot];
    meas_.clamp_estimate_kN[slot] = est;
    estimate_kN_[slot] = est;
    meas_.available[slot] = v.available;
  }
  const brake::BrakeOutput& out = brake_.update(period_s_, meas_);
  std::array<std::optional<double>, 4> cmd;
  for (std::size_t slot = 0; slot < 4; ++slot) {
    command_kN_[slot] = out.clamp_force_kN[slot];
    cmd[slot] = out.clamp_force_kN[slot];
  }
  ccu.set_brake_commands(cmd);
  return out;
}

}  // namespace bbw::vehicle_run
