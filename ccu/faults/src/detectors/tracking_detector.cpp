#include "bbw/faults/detectors/tracking_detector.hpp"

#include <algorithm>
#include <cmath>

#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

void TrackingDetector::update(const SampleContext& c, double force_estimate_kN, double friction_kN,
                              double clamp_upper_kN, double clamp_lower_kN, const MonitorParams& p,
                              DiagnosisArbiter& a) {
  const CornerReading& r = c.r;
  const double t = r.time_s;
  const double cmd = r.force_command_kN;
  if (!std::isfinite(cmd) || !std::isfinite(force_estimate_kN)) {
    model_init_ = false;
    tracking_suspect_ = excess_suspect_ = false;
    return;
  }
  if (!model_init_ || c.dt_s <= 0.0) {
    model_init_ = true;
    model_kN_ = force_estimate_kN;
  } else {
    model_kN_ += (cmd - model_kN_) * -std::expm1(-c.dt_s / p.tracking_time_constant_s);
  }
  // A drive at full speed towards its command: the response cannot be faster.
  const double full_speed = p.tracking_full_speed_fraction * p.drive_max_speed_rev_per_s;
  if (full_speed > 0.0 && std::abs(r.speed_rev_per_s) >= full_speed &&
      (r.speed_rev_per_s > 0.0) == (cmd > force_estimate_kN)) {
    model_kN_ = force_estimate_kN;
  }
  // A shortfall counts below both the command and the model, an excess above both (a release
  // faster than the model, or an apply faster than it, is not a fault).
  const double limit = std::max(p.tracking_threshold_kN, p.tracking_relative * std::abs(cmd));
  const bool reachable = cmd <= p.force_limit_kN;
  // Friction above zero holds the clamp force below the load cell (so below the command), below
  // zero above it.
  const double f = std::isfinite(friction_kN) ? friction_kN : 0.0;
  double reached_kN = force_estimate_kN + std::max(f, 0.0);
  if (p.tracking_shortfall_position_bound) {
    reached_kN = std::max(reached_kN, std::isfinite(clamp_lower_kN) ? std::max(0.0, clamp_lower_kN) : 0.0);
  }
  if (reachable && std::min(cmd, model_kN_) - reached_kN > limit) {
    if (!tracking_suspect_) {
      tracking_suspect_ = true;
      tracking_onset_s_ = t;
    }
    if (t - tracking_onset_s_ >= p.tracking_persist_s) a.confirm(Finding::ActuatorTracking, tracking_onset_s_, t);
  } else {
    tracking_suspect_ = false;
  }
  // Over-application: the brake holds a force well above what it is told and was told. Any
  // command counts (a brake told to release must release, whatever the force limit).
  const bool moving_back = r.speed_rev_per_s < -p.release_min_speed_rev_per_s;
  double held_kN = force_estimate_kN + std::min(f, 0.0);
  if (p.tracking_excess_position_bound && std::isfinite(clamp_upper_kN)) held_kN = std::min(held_kN, clamp_upper_kN);
  if (!moving_back && held_kN - std::max(cmd, model_kN_) > limit) {
    if (!excess_suspect_) {
      excess_suspect_ = true;
      excess_onset_s_ = t;
    }
    if (t - excess_onset_s_ >= p.tracking_persist_s) a.confirm(Finding::ActuatorNotReleasing, excess_onset_s_, t);
  } else {
    excess_suspect_ = false;
  }
}

}  // namespace bbw::faults
