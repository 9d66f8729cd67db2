// Load cell dropout: consecutive samples without a load-cell value (LoadCellMissing).
#pragma once

#include "bbw/faults/detectors/detector.hpp"

namespace bbw::faults {

class DropoutDetector {
 public:
  void update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a);
  void on_rejoin() { missing_run_ = 0; }

 private:
  int missing_run_ = 0;
  double missing_onset_s_ = 0.0;
};

}  // namespace bbw::faults
