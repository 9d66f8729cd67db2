// Load cell dropout: consecutive samples without a load-cell value (LoadCellMissing); a dropout
// finding clears once values are back for dropout_clear_samples in a row (issue 14).
#pragma once

#include "bbw/faults/detectors/detector.hpp"

namespace bbw::faults {

class DropoutDetector {
 public:
  void update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a);
  void on_rejoin() { missing_run_ = 0; }
  bool take_cleared() {
    const bool c = cleared_;
    cleared_ = false;
    return c;
  }

 private:
  int missing_run_ = 0;
  int present_run_ = 0;
  bool cleared_ = false;
  double missing_onset_s_ = 0.0;
};

}  // namespace bbw::faults
