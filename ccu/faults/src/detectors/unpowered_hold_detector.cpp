#include "bbw/faults/detectors/unpowered_hold_detector.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

void UnpoweredHoldDetector::track_coast(const SampleContext& c, const MonitorParams& p) {
  const CornerReading& r = c.r;
  // A live resolver changes its position or its (unquantised) speed every sample; a frozen one
  // repeats both exactly (StuckDetector's test).
  const bool live = !c.have_prev || r.position_rev != c.prev.position_rev || r.speed_rev_per_s != c.prev.speed_rev_per_s;
  if (live || !have_coast_) {
    forward_bound_rev_per_s_ = std::isfinite(r.speed_rev_per_s) ? std::max(0.0, r.speed_rev_per_s) : 0.0;
    have_coast_ = true;
    return;
  }
  const double current_A = std::isfinite(r.motor_current_A) ? r.motor_current_A : 0.0;
  const double load_kN =
      std::isfinite(r.force_kN) ? std::max(0.0, r.force_kN - p.eol_friction_half_width_kN) : 0.0;
  const double w = forward_bound_rev_per_s_;
  const double net_Nm = p.torque_per_A_Nm * current_A - p.Nm_per_kN * load_kN - plant::drive_friction_Nm(p.drive, w);
  forward_bound_rev_per_s_ = std::max(0.0, w + net_Nm / (2.0 * std::numbers::pi * p.inertia_kg_m2) * c.dt_s);
}

void UnpoweredHoldDetector::update(const SampleContext& c, bool commutation_lost, const MonitorParams& p,
                                   DiagnosisArbiter& a) {
  const CornerReading& r = c.r;
  track_coast(c, p);
  const double speed_rev_per_s =
      p.unpowered_coast_bound ? std::max(std::abs(r.speed_rev_per_s), forward_bound_rev_per_s_) : std::abs(r.speed_rev_per_s);
  const bool unpowered = p.unpowered_hold && commutation_lost && a.ok(Part::LoadCell) && c.check.load_cell_present &&
                         std::isfinite(r.force_kN) &&
                         std::isfinite(r.motor_current_A) && std::abs(r.motor_current_A) <= p.unpowered_max_current_A &&
                         speed_rev_per_s <= p.unpowered_max_speed_rev_per_s && c.have_prev &&
                         c.dt_s <= p.jump_max_gap_s;
  if (!unpowered) {
    reset();
    return;
  }
  const double t = r.time_s;
  lc_[static_cast<std::size_t>(head_)] = r.force_kN;
  head_ = (head_ + 1) % kMaxWindow;
  count_ = std::min(count_ + 1, kMaxWindow);
  const int n = p.unpowered_settle_samples;
  if (count_ < n) return;
  double sum = 0.0;
  for (int k = 1; k <= n; ++k) sum += lc_[static_cast<std::size_t>((head_ - k + kMaxWindow) % kMaxWindow)];
  const double mean = sum / n;
  const double loaded_kN = p.eol_friction_half_width_kN + p.eol_band_kN + p.unpowered_min_load_margin_kN;
  if (mean < loaded_kN) {  // the pads may be off: the keys' friction may vanish when the unseen drive stops
    have_ref_ = false;
    over_ = false;
    return;
  }
  // The level may fall (the load drives the spindle back, the keys' friction turns with it), never rise.
  ref_kN_ = have_ref_ ? std::min(ref_kN_, mean) : mean;
  have_ref_ = true;
  if (r.force_kN - ref_kN_ > p.unpowered_kN) {
    if (!over_) {
      over_ = true;
      over_since_s_ = t;
    }
    if (t - over_since_s_ >= p.residual_persist_s - 1e-9) a.confirm(Finding::LoadCellOffset, over_since_s_, t);
  } else {
    over_ = false;
  }
}

}  // namespace bbw::faults
