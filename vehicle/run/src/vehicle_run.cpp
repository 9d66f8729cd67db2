#include "bbw/vehicle_run/vehicle_run.hpp"

#include <cmath>
#include <stdexcept>

#include "bbw/scenario/scenario.hpp"

namespace bbw::vehicle_run {

namespace {
constexpr double kLockSpeed_m_s = 15.0 / 3.6;
}

VehicleRun::VehicleRun(const VehicleScenario& s, const calibration::CalibratorConfig& calibrator, const VehicleRunOptions& options)
    : scenario_(s),
      options_(options),
      run_(s.corners.scenario, calibrator, [&] {
        node::InProcessOptions o = options.in_process;
        o.schedule = s.corners.faults;
        return o;
      }()),
      vehicle_(s.vehicle.vehicle, s.road),
      pedal_(s.vehicle.pedal, s.pedal, scenario::corner_seed(s.seed, 100)),
      imu_(s.vehicle.imu, scenario::corner_seed(s.seed, 101)),
      brake_(s.brake) {
  if (options.exchange_every_samples < 1) throw std::invalid_argument("exchange_every_samples must be >= 1");
  dt_s_ = s.corners.scenario.plant_dt_s;
  vehicle_.reset(s.initial_speed_m_s, s.disc_C, s.caliper_C);
  for (std::size_t w = 0; w < 4; ++w) {
    wheel_sensors_.emplace_back(s.vehicle.wheel_speed, scenario::corner_seed(s.seed, 110 + w));
    wheel_sensors_.back().reset(0.0, 0.0);
  }
  if (s.driver) driver_.emplace(s.driver_params, s.vehicle.vehicle.chassis.wheelbase_m());
  for (std::size_t i = 0; i < run_.corners(); ++i) {
    blocks_in_[i] = run_.block_topic(i).receiver();
    slot_of_channel_[i] = run_.ccu().channel(i).slot;
  }
  vehicle_participant_ = run_.ccu().add_participant("vehicle");
  pedal_participant_ = run_.ccu().add_participant("pedal");
  run_.set_period_hook([this](std::uint64_t k) { vehicle_period(k); });
  // Before the first period the wheels roll at the start speed.
  for (std::size_t w = 0; w < 4; ++w) meas_.wheel_rad_s[w] = vehicle_.state().wheels[w].spin_rad_s;
}

double VehicleRun::caliper_temperature_C(std::size_t slot) const { return vehicle_.state().wheels[slot].caliper_C; }

void VehicleRun::vehicle_period(std::uint64_t k) {
  // The corners' true clamp forces of period k, per wheel slot, one per plant step.
  const std::size_t n = static_cast<std::size_t>(std::llround(run_.ccu().period_end_s(k) / dt_s_)) -
                        static_cast<std::size_t>(std::llround(run_.ccu().period_start_s(k) / dt_s_));
  std::array<std::array<double, 64>, 4> force{};
  for (std::size_t w = 0; w < 4; ++w) force[w].fill(0.0);
  std::array<bool, 4> got{};
  for (std::size_t i = 0; i < run_.corners(); ++i) {
    const std::size_t slot = slot_of_channel_[i];
    while (blocks_in_[i]->take(block_)) {
      const auto& samples = block_.samples();
      for (std::size_t j = 0; j < samples.size() && j < 64; ++j) force[slot][j] = samples[j].force_true_kN();
      got[slot] = got[slot] || !samples.empty();
      if (!samples.empty()) last_force_kN_[slot] = samples.back().force_true_kN();
      for (std::size_t j = samples.size(); j < n && j < 64; ++j) force[slot][j] = last_force_kN_[slot];
    }
    // A corner whose process is gone sends nothing: its caliper is assumed to release.
    if (!got[slot] && !run_.corner_alive(i)) last_force_kN_[slot] = 0.0;
    if (!got[slot]) force[slot].fill(last_force_kN_[slot]);
  }
  vehicle::VehicleInputs in;
  double ax = 0.0, ay = 0.0, r = 0.0;
  const int every = options_.exchange_every_samples;
  for (std::size_t j = 0; j < n; ++j) {
    const std::uint64_t global = k * n + j;
    for (std::size_t w = 0; w < 4; ++w) {
      if (every == 1 || global % static_cast<std::uint64_t>(every) == 0) in.clamp_force_kN[w] = force[w][j];
    }
    const vehicle::VehicleState& st = vehicle_.state();
    if (driver_) in.steer_rad = driver_->steer(dt_s_, st.x_m, st.y_m, st.yaw_rad, vehicle_.speed_m_s(), st.yaw_rate_rad_s);
    vehicle_.step(dt_s_, in);
    const vehicle::VehicleState& s = vehicle_.state();
    for (std::size_t w = 0; w < 4; ++w) wheel_sensors_[w].update(s.wheels[w].angle_rad, s.time_s);
    const vehicle::ImuReading imu = imu_.read(s.ax_m_s2, s.ay_m_s2, s.yaw_rate_rad_s);
    ax += imu.ax_m_s2 / static_cast<double>(n);
    ay += imu.ay_m_s2 / static_cast<double>(n);
    r += imu.yaw_rate_rad_s / static_cast<double>(n);
    // Metrics at the plant step.
    const double v = vehicle_.speed_m_s();
    if (onset_s_ < 0.0 && pedal_.travel_fraction(s.time_s) > 0.0) {
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
  // The vehicle's sensor block for period k, and the pedal's.
  const double t_end = vehicle_.state().time_s;
  for (std::size_t w = 0; w < 4; ++w) meas_.wheel_rad_s[w] = wheel_sensors_[w].speed_rad_s(t_end);
  meas_.ax_m_s2 = ax;
  meas_.ay_m_s2 = ay;
  meas_.yaw_rate_rad_s = r;
  const vehicle::PedalReading pr = pedal_.read(t_end);
  meas_.pedal_travel_mm = pr.travel_mm;
  meas_.pedal_force_N = pr.force_N;
  // The caliper temperatures the vehicle computed reach the corners' plants from the next period
  // (over DDS they would travel in the vehicle's message; in process the node is at hand).
  for (std::size_t i = 0; i < run_.corners(); ++i) {
    run_.corner(i).set_caliper_temperature_C(caliper_temperature_C(slot_of_channel_[i]));
  }
  run_.ccu().participant_done(vehicle_participant_, k);
  run_.ccu().participant_done(pedal_participant_, k);
  // Trace.
  PeriodTrace t;
  const vehicle::VehicleState& s = vehicle_.state();
  t.time_s = t_end;
  t.speed_m_s = vehicle_.speed_m_s();
  t.speed_estimate_m_s = brake_.last().speed_estimate_m_s;
  t.x_m = s.x_m;
  t.y_m = s.y_m;
  t.yaw_rad = s.yaw_rad;
  t.yaw_rate_rad_s = s.yaw_rate_rad_s;
  t.ax_m_s2 = s.ax_m_s2;
  t.path_m = s.path_m;
  t.steer_rad = in.steer_rad;
  t.demand = brake_.last().demand;
  t.stopped = s.stopped;
  for (std::size_t w = 0; w < 4; ++w) {
    const auto& o = vehicle_.wheels()[w];
    t.wheel_speed_m_s[w] = s.wheels[w].spin_rad_s * scenario_.vehicle.vehicle.chassis.wheel_radius_m;
    t.slip[w] = -o.slip;
    t.mu_used[w] = o.mu_used;
    t.surface_mu_scale[w] = o.surface_mu_scale;
    t.command_kN[w] = command_kN_[w];
    t.clamp_true_kN[w] = force[w][n > 0 ? n - 1 : 0];
    t.clamp_estimate_kN[w] = estimate_kN_[w];
    t.brake_torque_Nm[w] = o.brake_torque_Nm;
    t.disc_C[w] = s.wheels[w].disc_C;
    t.abs_active[w] = brake_.last().wheels[w].active;
    t.target_slip[w] = brake_.last().wheels[w].target_slip;
  }
  trace_.push_back(t);
}

bool VehicleRun::step() {
  const std::uint64_t k = run_.periods_done();
  if (k < run_.ccu().periods()) {
    // The CCU's brake functions for period k from the readings at the end of k - 1.
    const double period = scenario_.corners.scenario.ccu_period_s;
    for (std::size_t slot = 0; slot < 4; ++slot) {
      const faults::CornerView& v = run_.ccu().core().supervisor(slot).view();
      const double est = v.estimate_valid() && std::isfinite(v.force_estimate_kN) ? v.force_estimate_kN : command_kN_[slot];
      meas_.clamp_estimate_kN[slot] = est;
      estimate_kN_[slot] = est;
      meas_.available[slot] = v.available;
    }
    const brake::BrakeOutput& out = brake_.update(period, meas_);
    std::array<std::optional<double>, 4> cmd;
    for (std::size_t slot = 0; slot < 4; ++slot) {
      command_kN_[slot] = out.clamp_force_kN[slot];
      cmd[slot] = out.clamp_force_kN[slot];
    }
    run_.ccu().set_brake_commands(cmd);
  }
  return run_.step();
}

void VehicleRun::run() {
  while (step()) {
  }
}

}  // namespace bbw::vehicle_run
