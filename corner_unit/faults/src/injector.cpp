#include "bbw/faults/injector.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace bbw::faults {

FaultInjector::FaultInjector(const FaultSchedule& schedule, Target corner, std::uint64_t noise_seed)
    : corner_(corner), rng_(noise_seed) {
  if (!corner_slot(corner)) throw std::invalid_argument("FaultInjector: the CCU has no sensors or actuator");
  for (const FaultSpec& f : schedule.faults) {
    if (f.target != corner) continue;
    if (f.part == Part::LoadCell || f.part == Part::Resolver || f.part == Part::Actuator) faults_.push_back(f);
  }
}

void FaultInjector::apply(plant::Measurement& m) {
  const double t = m.time_s;
  bool lc_stuck = false;
  bool res_stuck = false;
  for (const FaultSpec& f : faults_) {
    if (!f.active_at(t)) continue;
    if (f.part == Part::LoadCell) {
      switch (f.type) {
        case FaultType::Bias: m.force_internal_kN += f.bias_kN; break;
        case FaultType::Drift: m.force_internal_kN += f.rate_kN_per_s * (t - f.at_s); break;
        case FaultType::NoiseBurst: m.force_internal_kN += f.rms_kN * normal_(rng_); break;
        case FaultType::Dropout: m.force_internal_kN = std::numeric_limits<double>::quiet_NaN(); break;
        case FaultType::Stuck: lc_stuck = true; break;
        default: break;
      }
    } else if (f.part == Part::Resolver) {
      if (f.type == FaultType::Offset) m.position_rev += f.offset_rev;
      if (f.type == FaultType::Stuck) res_stuck = true;
    }
  }
  // A stuck channel repeats the value it delivered just before the fault began.
  if (lc_stuck) {
    if (!load_cell_stuck_) stuck_load_cell_kN_ = have_previous_ ? previous_.force_internal_kN : m.force_internal_kN;
    m.force_internal_kN = stuck_load_cell_kN_;
  }
  if (res_stuck) {
    if (!resolver_stuck_) {
      stuck_position_rev_ = have_previous_ ? previous_.position_rev : m.position_rev;
      stuck_speed_rev_per_s_ = have_previous_ ? previous_.speed_rev_per_s : m.speed_rev_per_s;
    }
    m.position_rev = stuck_position_rev_;
    m.speed_rev_per_s = stuck_speed_rev_per_s_;
  }
  load_cell_stuck_ = lc_stuck;
  resolver_stuck_ = res_stuck;
  previous_ = m;
  have_previous_ = true;
}

double FaultInjector::torque_scale(double time_s) const {
  double scale = 1.0;
  for (const FaultSpec& f : faults_) {
    if (f.part != Part::Actuator || !f.active_at(time_s)) continue;
    if (f.type == FaultType::TotalLoss) scale = 0.0;
    if (f.type == FaultType::TorqueLoss) scale *= 1.0 - f.torque_loss_percent / 100.0;
  }
  return std::clamp(scale, 0.0, 1.0);
}

bool FaultInjector::seized(double time_s) const {
  return std::any_of(faults_.begin(), faults_.end(), [&](const FaultSpec& f) {
    return f.part == Part::Actuator && f.type == FaultType::Seized && f.active_at(time_s);
  });
}

void FaultInjector::prepare(scenario::ExternalInputs& ext, double step_end_s) {
  ext.sensor_hook = this;
  ext.torque_scale = torque_scale(step_end_s);
  ext.actuator_seized = seized(step_end_s);
}

bool FaultInjector::any_active(double time_s) const {
  return std::any_of(faults_.begin(), faults_.end(), [&](const FaultSpec& f) { return f.active_at(time_s); });
}

}  // namespace bbw::faults
