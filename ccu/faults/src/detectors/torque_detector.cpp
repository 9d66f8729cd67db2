#include "bbw/faults/detectors/torque_detector.hpp"

#include <cmath>

#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

void TorqueDetector::update(const SampleContext& c, double load_kN, const MonitorParams& p, DiagnosisArbiter& a) {
  const CornerReading& r = c.r;
  const double t = r.time_s;
  const double accel = c.have_prev && c.dt_s > 0.0 ? (r.speed_rev_per_s - c.prev.speed_rev_per_s) / c.dt_s : 0.0;
  // A frozen resolver repeats its last (noisy, so nonzero) speed exactly.
  const bool repeated = c.have_prev && r.speed_rev_per_s != 0.0 && r.speed_rev_per_s == c.prev.speed_rev_per_s;
  speed_repeats_ = repeated ? speed_repeats_ + 1 : 0;
  if (!a.ok(Part::Resolver) || !std::isfinite(load_kN) || speed_repeats_ >= p.frozen_attribution_samples) {
    torque_init_ = torque_suspect_ = lost_suspect_ = false;
    return;
  }
  constexpr double kTwoPi = 6.283185307179586;
  const double need = load_kN * p.Nm_per_kN + p.inertia_kg_m2 * kTwoPi * accel;
  const double make = r.motor_current_A * p.torque_per_A_Nm;
  if (!torque_init_ || c.dt_s <= 0.0) {
    torque_init_ = true;
    need_Nm_ = need;
    make_Nm_ = make;
  } else {
    const double k = -std::expm1(-c.dt_s / p.torque_filter_s);
    need_Nm_ += (need - need_Nm_) * k;
    make_Nm_ += (make - make_Nm_) * k;
  }
  const bool checkable = load_kN >= p.torque_check_min_load_kN && make_Nm_ >= p.torque_check_min_torque_Nm;
  const double fraction = checkable ? need_Nm_ / make_Nm_ : 1.0;
  if (checkable) fraction_ = fraction;
  if (checkable && fraction < p.torque_lost_threshold) {
    if (!lost_suspect_) {
      lost_suspect_ = true;
      lost_onset_s_ = t;
    }
    if (t - lost_onset_s_ >= p.torque_lost_persist_s) a.confirm(Finding::ActuatorLost, lost_onset_s_, t);
  } else {
    lost_suspect_ = false;
  }
  const bool still = std::abs(r.speed_rev_per_s) <= p.torque_check_max_speed_rev_per_s;
  if (checkable && still && fraction < p.torque_fraction_threshold) {
    if (!torque_suspect_) {
      torque_suspect_ = true;
      torque_onset_s_ = t;
    }
    if (t - torque_onset_s_ >= p.torque_persist_s) a.confirm(Finding::ActuatorTorqueLoss, torque_onset_s_, t);
  } else {
    torque_suspect_ = false;
  }
}

}  // namespace bbw::faults
