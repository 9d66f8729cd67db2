// DIR/report.html with PNG plots drawn by gnuplot from the CCU's per-corner logs.
#pragma once

#include <string>
#include <vector>

#include "fault_report.hpp"
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

// Throws std::runtime_error when gnuplot fails (the message names the script). With `faults`,
// the report also shows the total clamp force against demand (DIR/timeline.csv) with the
// injections and detections marked, and the fault table.
void write_report(const std::string& dir, const std::string& title, const std::vector<ReportCorner>& corners,
                  const std::string& summary_json, const std::vector<FaultResult>* faults = nullptr,
                  const std::vector<Detection>* detections = nullptr);

}  // namespace bbw::launch
