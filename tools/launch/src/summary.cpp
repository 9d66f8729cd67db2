#include "summary.hpp"

#include <cmath>

namespace bbw::launch {

csv::ReadOptions ccu_log_columns() {
  csv::ReadOptions o;
  // Samples whose estimate is invalid (NaN) are rejected by the reader: they are not scored.
  o.required = {"time_s",  "position_rev", "force_internal_kN", "force_true_kN", "command", "force_mode",
                "estimate_kN", "curve_kN", "fused_kN", "valid", "calibrated"};
  return o;
}

CornerSummary summarize_corner(const std::string& corner, const csv::Table& log) {
  CornerSummary s;
  s.corner = corner;
  const auto& lc = log.column("force_internal_kN");
  const auto& truth = log.column("force_true_kN");
  const auto& cmd = log.column("command");
  const auto& force_mode = log.column("force_mode");
  const auto& est = log.column("estimate_kN");
  const auto& fused = log.column("fused_kN");
  const auto& valid = log.column("valid");
  const auto& calibrated = log.column("calibrated");
  const auto& time = log.column("time_s");
  s.samples = log.rows();
  double fused_sq = 0.0, comp_sq = 0.0, lc_sq = 0.0, track_sq = 0.0, steady_sq = 0.0;
  double held_cmd = 0.0, held_since_s = 0.0;
  for (std::size_t i = 0; i < log.rows(); ++i) {
    if (force_mode[i] > 0.5) {
      const double e = truth[i] - cmd[i];
      track_sq += e * e;
      s.tracking_max_abs_error_kN = std::max(s.tracking_max_abs_error_kN, std::fabs(e));
      ++s.force_samples;
      if (std::fabs(cmd[i] - held_cmd) > 0.05) {
        held_cmd = cmd[i];
        held_since_s = time[i];
      } else if (time[i] - held_since_s >= 0.3 && cmd[i] > 0.5) {
        steady_sq += e * e;
        s.tracking_steady_max_abs_error_kN = std::max(s.tracking_steady_max_abs_error_kN, std::fabs(e));
        ++s.steady_samples;
      }
    }
    if (valid[i] < 0.5 || calibrated[i] < 0.5) continue;
    const double ef = fused[i] - truth[i];
    const double ec = est[i] - truth[i];
    const double el = lc[i] - truth[i];
    fused_sq += ef * ef;
    comp_sq += ec * ec;
    lc_sq += el * el;
    s.fused_max_abs_error_kN = std::max(s.fused_max_abs_error_kN, std::fabs(ef));
    s.compensated_max_abs_error_kN = std::max(s.compensated_max_abs_error_kN, std::fabs(ec));
    ++s.samples_scored;
  }
  if (s.samples_scored > 0) {
    const double n = static_cast<double>(s.samples_scored);
    s.fused_rms_error_kN = std::sqrt(fused_sq / n);
    s.compensated_rms_error_kN = std::sqrt(comp_sq / n);
    s.load_cell_rms_error_kN = std::sqrt(lc_sq / n);
  }
  if (s.force_samples > 0) s.tracking_rms_error_kN = std::sqrt(track_sq / static_cast<double>(s.force_samples));
  if (s.steady_samples > 0) s.tracking_steady_rms_error_kN = std::sqrt(steady_sq / static_cast<double>(s.steady_samples));
  return s;
}

}  // namespace bbw::launch
