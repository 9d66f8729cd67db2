// DIR/report.html with PNG plots drawn by gnuplot from the CCU's per-corner logs.
#pragma once

#include <string>
#include <vector>

#include "summary.hpp"

namespace bbw::launch {

struct CurveCoefficients {
  double a = 0.0, b = 0.0, c = 0.0, d = 0.0;
};

struct ReportCorner {
  CornerSummary summary;
  CurveCoefficients curve;
  bool calibrated = false;
};

// Throws std::runtime_error when gnuplot fails (the message names the script).
void write_report(const std::string& dir, const std::string& title, const std::vector<ReportCorner>& corners,
                  const std::string& summary_json);

}  // namespace bbw::launch
