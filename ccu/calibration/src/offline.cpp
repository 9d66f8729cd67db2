#include "bbw/calibration/offline.hpp"

#include <cmath>
#include <stdexcept>

namespace bbw::calibration {

Score score_estimates(const Recording& rec, const std::vector<Estimate>& est, double first_fit_time_s,
                      double full_scale_kN) {
  Score s;
  if (rec.time_s.empty()) return s;
  s.warmup_s = first_fit_time_s < 0.0 ? -1.0 : first_fit_time_s - rec.time_s.front();
  if (rec.truth_kN.size() != rec.time_s.size() || first_fit_time_s < 0.0) return s;
  double sse = 0.0;
  for (std::size_t k = 0; k < est.size(); ++k) {
    if (!est[k].valid || rec.time_s[k] < first_fit_time_s) continue;
    const double err = est[k].force_kN - rec.truth_kN[k];
    sse += err * err;
    ++s.samples_scored;
    if (std::fabs(err) > s.max_abs_error_kN) {
      s.max_abs_error_kN = std::fabs(err);
      s.time_of_max_error_s = rec.time_s[k];
    }
  }
  if (s.samples_scored > 0) s.rms_error_kN = std::sqrt(sse / static_cast<double>(s.samples_scored));
  s.max_error_pct_fs = 100.0 * s.max_abs_error_kN / full_scale_kN;
  return s;
}

OfflineResult run_recording(const CalibratorConfig& config, const Recording& rec) {
  const std::size_t n = rec.time_s.size();
  if (rec.position_rev.size() != n || rec.force_kN.size() != n || (!rec.speed_rev_per_s.empty() && rec.speed_rev_per_s.size() != n) ||
      (!rec.temperature_C.empty() && rec.temperature_C.size() != n)) {
    throw std::invalid_argument("run_recording: the recording's columns differ in length");
  }
  Calibrator cal(config);
  OfflineResult out;
  out.estimates.reserve(rec.time_s.size());
  for (std::size_t k = 0; k < rec.time_s.size(); ++k) {
    Sample s{rec.time_s[k], rec.position_rev[k], rec.force_kN[k]};
    if (!rec.speed_rev_per_s.empty()) s.speed_rev_per_s = rec.speed_rev_per_s[k];
    if (!rec.temperature_C.empty()) s.temperature_C = rec.temperature_C[k];
    out.estimates.push_back(cal.update(s));
  }
  out.stats = cal.stats();
  out.curve = cal.curve();
  out.friction = cal.friction();
  out.score = score_estimates(rec, out.estimates, cal.stats().first_fit_time_s, config.full_scale_kN);
  return out;
}

}  // namespace bbw::calibration
