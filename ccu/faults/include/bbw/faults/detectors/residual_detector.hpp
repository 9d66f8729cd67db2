// Analytic redundancy: r = (load cell - friction estimate) - curve(position), where the curve is
// trusted. A residual beyond its threshold (wider before the first accepted fit), or a change
// against its own recent level beyond residual_change_threshold_kN, that persists is a
// disagreement; isolation names the channel that explains it (a frozen position: ResolverStuck;
// a frozen load cell: LoadCellStuck; a recent position jump: ResolverOffset; else
// LoadCellOffset). Feeds the noise detector with every residual.
#pragma once

#include <limits>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/faults/detectors/detector.hpp"
#include "bbw/faults/detectors/jump_detector.hpp"
#include "bbw/faults/detectors/noise_detector.hpp"
#include "bbw/faults/detectors/stuck_detector.hpp"

namespace bbw::faults {

class ResidualDetector {
 public:
  ResidualDetector(double curve_min_rev, double curve_max_rev) : curve_min_rev_(curve_min_rev), curve_max_rev_(curve_max_rev) {}
  void update(const CornerReading& r, const calibration::Estimate& e, const MonitorParams& p, DiagnosisArbiter& a,
              NoiseDetector& noise, const StuckDetector& stuck, const JumpDetector& jump);
  void on_rejoin() { suspect_ = false; }
  void set_curve_range(double min_rev, double max_rev) {
    curve_min_rev_ = min_rev;
    curve_max_rev_ = max_rev;
  }
  double residual_kN() const { return residual_kN_; }
  // A disagreement is under way but not yet confirmed (persist_s).
  bool suspect() const { return suspect_; }
  double change_kN() const { return change_kN_; }

 private:
  bool suspect_ = false;
  double onset_s_ = 0.0;
  double residual_kN_ = std::numeric_limits<double>::quiet_NaN();
  double change_kN_ = std::numeric_limits<double>::quiet_NaN();
  bool have_reference_ = false;
  bool reference_calibrated_ = false;  // the calibrator's state when the reference was set
  double reference_kN_ = 0.0;
  double reference_time_s_ = 0.0;
  double curve_min_rev_;
  double curve_max_rev_;
};

}  // namespace bbw::faults
