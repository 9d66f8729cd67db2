#include "bbw/faults/detectors/unpowered_hold_detector.hpp"

#include <algorithm>
#include <cmath>

#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

void UnpoweredHoldDetector::update(const SampleContext& c, bool commutation_lost, const MonitorParams& p,
                                   DiagnosisArbiter& a) {
  const CornerReading& r = c.r;
  const bool unpowered = p.unpowered_hold && commutation_lost && a.ok(Part::LoadCell) && c.check.load_cell_present &&
                         std::isfinite(r.force_kN) &&
                         std::isfinite(r.motor_current_A) && std::abs(r.motor_current_A) <= p.unpowered_max_current_A &&
                         std::abs(r.speed_rev_per_s) <= p.unpowered_max_speed_rev_per_s && c.have_prev &&
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
