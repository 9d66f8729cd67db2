#include "bbw/vehicle_run/vehicle_run.hpp"

#include <cmath>
#include <stdexcept>

namespace bbw::vehicle_run {

VehicleRun::VehicleRun(const VehicleScenario& s, const calibration::CalibratorConfig& calibrator, const VehicleRunOptions& options)
    : scenario_(s),
      options_(options),
      run_(s.corners.scenario, calibrator, [&] {
        node::InProcessOptions o = options.in_process;
        o.schedule = s.corners.faults;
        return o;
      }()),
      vehicle_(s, options.exchange_every_samples),
      pedal_(s),
      brake_(s.brake, s.corners.scenario.ccu_period_s, vehicle_.vehicle().state()) {
  for (std::size_t i = 0; i < run_.corners(); ++i) {
    blocks_in_[i] = run_.block_topic(i).receiver();
    slot_of_channel_[i] = run_.ccu().channel(i).slot;
  }
  vehicle_participant_ = run_.ccu().add_participant("vehicle");
  pedal_participant_ = run_.ccu().add_participant("pedal");
  run_.set_period_hook([this](std::uint64_t k) { vehicle_period(k); });
  run_.ccu().set_curve_feedback(options.curve_feedback);
  trace_.reserve(static_cast<std::size_t>(run_.ccu().periods()) + 2);
}

// The vehicle's and the pedal's period k, after the corners' (InProcessRun's period hook): the
// vehicle takes the corners' blocks of k from its own subscriptions, as bbw_vehicle over DDS.
void VehicleRun::vehicle_period(std::uint64_t k) {
  const std::size_t n = static_cast<std::size_t>(std::llround(run_.ccu().period_end_s(k) / scenario_.corners.scenario.plant_dt_s)) -
                        static_cast<std::size_t>(std::llround(run_.ccu().period_start_s(k) / scenario_.corners.scenario.plant_dt_s));
  for (std::size_t i = 0; i < run_.corners(); ++i) {
    while (blocks_in_[i]->take(block_)) vehicle_.on_block(slot_of_channel_[i], block_);
    if (!run_.corner_alive(i)) vehicle_.corner_lost(slot_of_channel_[i]);
  }
  const msg::VehicleSensors& sensors = vehicle_.simulate_period(k, n);
  // The pedal reads at the period's end as the node computes it (bbw_pedal does the same).
  const msg::PedalSample& pedal = pedal_.sample(k, run_.ccu().period_end_s(k));
  brake_.on_vehicle(sensors);
  brake_.on_pedal(pedal);
  // Every N-th period the caliper temperatures the vehicle computed reach the corners' plants, from
  // the next period on (bbw_vehicle's CaliperTemperatures; node::caliper_temperature_step).
  if (node::caliper_temperature_sent_after(k)) {
    for (std::size_t i = 0; i < run_.corners(); ++i) {
      run_.corner(i).set_caliper_temperature_C(sensors.caliper_temperature_C()[slot_of_channel_[i]]);
    }
  }
  run_.ccu().participant_done(vehicle_participant_, k);
  run_.ccu().participant_done(pedal_participant_, k);
  const TruthRow& t = vehicle_.truth().back();
  PeriodTrace p;
  p.time_s = t.time_s;
  p.speed_m_s = t.speed_m_s;
  p.speed_estimate_m_s = brake_.controller().last().speed_estimate_m_s;
  p.x_m = t.x_m;
  p.y_m = t.y_m;
  p.yaw_rad = t.yaw_rad;
  p.yaw_rate_rad_s = t.yaw_rate_rad_s;
  p.ax_m_s2 = t.ax_m_s2;
  p.path_m = t.path_m;
  p.steer_rad = t.steer_rad;
  p.demand = brake_.controller().last().demand;
  p.split_mu = brake_.controller().last().split_mu;
  p.stopped = t.stopped;
  for (std::size_t w = 0; w < 4; ++w) {
    p.wheel_speed_m_s[w] = t.wheel_speed_m_s[w];
    p.slip[w] = t.slip[w];
    p.mu_used[w] = t.mu_used[w];
    p.surface_mu_scale[w] = t.surface_mu_scale[w];
    p.command_kN[w] = command_kN_[w];
    p.clamp_true_kN[w] = t.clamp_true_kN[w];
    p.clamp_estimate_kN[w] = estimate_kN_[w];
    p.brake_torque_Nm[w] = t.brake_torque_Nm[w];
    p.disc_C[w] = t.disc_C[w];
    p.abs_active[w] = brake_.controller().last().wheels[w].active;
    p.target_slip[w] = brake_.controller().last().wheels[w].target_slip;
  }
  trace_.push_back(p);
}

bool VehicleRun::step() {
  if (run_.periods_done() < run_.ccu().periods()) {
    // The CCU's brake functions for period k from the readings at the end of k - 1.
    brake_.plan(run_.ccu());
    command_kN_ = brake_.commands_kN();
    estimate_kN_ = brake_.estimates_kN();
  }
  return run_.step();
}

void VehicleRun::run() {
  while (step()) {
  }
}

}  // namespace bbw::vehicle_run
