#include "bbw/faults/detectors/residual_detector.hpp"

#include <algorithm>
#include <cmath>

#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

void ResidualDetector::update(const CornerReading& r, const calibration::Estimate& e, const MonitorParams& p,
                              DiagnosisArbiter& a, NoiseDetector& noise, const StuckDetector& stuck,
                              const JumpDetector& jump) {
  const double t = r.time_s;
  residual_kN_ = e.force_kN - e.curve_force_kN;
  noise.update(residual_kN_, t, p, a);
  if (r.position_rev < curve_min_rev_ || r.position_rev > curve_max_rev_) {
    suspect_ = false;  // no trusted curve here
    residual_kN_ = std::numeric_limits<double>::quiet_NaN();
    change_kN_ = std::numeric_limits<double>::quiet_NaN();
    have_reference_ = false;  // restarts where the curve is trusted again
    return;
  }
  // The first accepted fit replaces the initial curve and adds the friction model, which moves
  // the residual by itself: the change rule restarts from the calibrated residual, unless a
  // fault is already suspected. (Later fits move it little; restarting at each of them too made
  // a slow drift 40 ms later to find.)
  if (e.calibrated != reference_calibrated_ && !suspect_) have_reference_ = false;
  if (!have_reference_) {
    have_reference_ = true;
    reference_calibrated_ = e.calibrated;
    reference_kN_ = residual_kN_;
    reference_time_s_ = t;
  }
  change_kN_ = residual_kN_ - reference_kN_;
  const double thr = e.calibrated ? p.residual_threshold_kN : p.uncalibrated_residual_threshold_kN;
  const bool over = p.residual_findings && (std::abs(residual_kN_) > thr ||
                                            (e.calibrated && std::abs(change_kN_) > p.residual_change_threshold_kN));
  if (!over) {
    suspect_ = false;
    const double dt = std::max(0.0, t - reference_time_s_);
    reference_kN_ += (residual_kN_ - reference_kN_) * -std::expm1(-dt / p.residual_reference_s);
    reference_time_s_ = t;
    return;
  }
  reference_time_s_ = t;  // frozen while suspected
  if (!suspect_) {
    suspect_ = true;
    onset_s_ = t;
  }
  if (t - onset_s_ < p.residual_persist_s) return;
  // Isolation: which channel explains the disagreement?
  const bool position_frozen = stuck.position_repeats() >= p.frozen_attribution_samples;
  const bool load_cell_frozen = stuck.load_cell_repeats() >= p.frozen_attribution_samples;
  Finding f = Finding::LoadCellOffset;
  if (position_frozen && !load_cell_frozen) {
    f = Finding::ResolverStuck;
  } else if (load_cell_frozen && !position_frozen) {
    f = Finding::LoadCellStuck;
  } else if (t - jump.last_jump_s() <= p.jump_window_s + p.residual_persist_s) {
    f = Finding::ResolverOffset;
  }
  a.confirm(f, onset_s_, t);
}

}  // namespace bbw::faults
