// The per-corner tracking errors of one bbw_launch summary.json, as bbw_compare_feedback compares
// them. A null error (nothing scored: summary.json writes null and tracking_not_scored_reason,
// never 0) is an error naming the file, the corner, the field and the reason.
#pragma once

#include <map>
#include <string>

namespace bbw::compare_feedback {

struct Tracking {
  double rms = 0, max = 0, steady_rms = 0, steady_max = 0;
  long long fits = 0;
};

// Throws std::runtime_error (file, corner, field, reason) on a null or missing value.
std::map<std::string, Tracking> read_summary(const std::string& file);

}  // namespace bbw::compare_feedback
