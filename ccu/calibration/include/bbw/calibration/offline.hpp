// Running the calibrator over a whole recording and scoring it against truth. Pure: the
// caller reads files; the same per-sample update() is used as in the CCU.
#pragma once

#include <vector>

#include "bbw/calibration/calibrator.hpp"

namespace bbw::calibration {

struct Recording {
  std::vector<double> time_s;
  std::vector<double> position_rev;
  std::vector<double> force_kN;   // internal load cell
  std::vector<double> truth_kN;   // external sensor / true clamp force; empty when absent
  std::vector<double> speed_rev_per_s;  // resolver speed; empty when absent
  std::vector<double> temperature_C;  // caliper temperature; empty when absent
};

struct Score {
  double max_abs_error_kN = 0.0;
  double rms_error_kN = 0.0;
  double max_error_pct_fs = 0.0;
  std::size_t samples_scored = 0;
  double warmup_s = -1.0;          // time from the first sample to the first accepted fit
  double time_of_max_error_s = 0.0;
};

struct OfflineResult {
  std::vector<Estimate> estimates;  // one per input sample
  Stats stats;
  Curve curve;
  FrictionParams friction;
  Score score;                      // only meaningful when truth was given
};

// Scores estimates against truth after the first accepted fit (errors before it are not scored).
Score score_estimates(const Recording& rec, const std::vector<Estimate>& est, double first_fit_time_s,
                      double full_scale_kN);

OfflineResult run_recording(const CalibratorConfig& config, const Recording& rec);

}  // namespace bbw::calibration
