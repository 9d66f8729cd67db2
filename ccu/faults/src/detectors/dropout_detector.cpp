#include "bbw/faults/detectors/dropout_detector.hpp"

#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

void DropoutDetector::update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a) {
  const double t = c.r.time_s;
  if (!c.check.load_cell_present) {
    present_run_ = 0;
    if (missing_run_ == 0) missing_onset_s_ = t;
    if (++missing_run_ >= p.dropout_samples) a.confirm(Finding::LoadCellMissing, missing_onset_s_, t);
  } else {
    missing_run_ = 0;
    const Diagnosis& d = a.diagnosis(Part::LoadCell);
    if (d.active && d.finding == Finding::LoadCellMissing && ++present_run_ >= p.dropout_clear_samples) {
      a.clear(Part::LoadCell);  // only a dropout: a value that is back is a value again
      cleared_ = true;
      present_run_ = 0;
    }
  }
}

}  // namespace bbw::faults
