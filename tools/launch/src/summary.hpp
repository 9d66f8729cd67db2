// Run summary from the CCU's per-sample logs and the processes' stats files. Pure arithmetic
// over tables; the launcher reads the files.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "bbw/common/csv.hpp"

namespace bbw::launch {

struct CornerSummary {
  std::string corner;
  std::size_t samples = 0;
  std::size_t samples_scored = 0;          // after the first accepted fit, estimate valid
  double fused_max_abs_error_kN = 0.0;     // fused estimate vs plant truth
  double fused_rms_error_kN = 0.0;
  double compensated_max_abs_error_kN = 0.0;  // load cell minus friction vs truth
  double compensated_rms_error_kN = 0.0;
  double load_cell_rms_error_kN = 0.0;     // raw load cell vs truth, same samples
  std::size_t force_samples = 0;           // samples under a clamp-force command
  double tracking_rms_error_kN = 0.0;      // true clamp force vs command
  // Holds only: samples whose command has stayed within 0.05 kN for 0.3 s (step transients,
  // bounded by the actuator's speed, excluded) and is above 0.5 kN.
  double tracking_steady_max_abs_error_kN = 0.0;
  double tracking_steady_rms_error_kN = 0.0;
  std::size_t steady_samples = 0;
  double tracking_max_abs_error_kN = 0.0;
};

// Table columns used: time_s, force_internal_kN, force_true_kN, command, force_mode,
// estimate_kN, fused_kN, valid, calibrated (the CCU's ccu_<corner>.csv).
CornerSummary summarize_corner(const std::string& corner, const csv::Table& log);

csv::ReadOptions ccu_log_columns();

}  // namespace bbw::launch
