// Load-cell step at standstill (issue 14): while the actuator has not moved for
// step.still_samples (its position within step.still_span_rev), the clamp force cannot change:
// the curve and the key friction are functions of the position's history, and the drive's
// speed-dependent effects are at rest. A load-cell reading that leaves the level of that still
// window by step.step_kN and stays beyond step.keep_fraction of the step for
// step.confirm_samples (noise returns, a bias stays; the force loop's reaction moves the key
// friction only a little within a few milliseconds) is a load-cell offset (LoadCellOffset), at
// any force, before the first fit and beyond the fitted range alike.
#pragma once

#include <array>

#include "bbw/faults/detectors/detector.hpp"

namespace bbw::faults {

class StepDetector {
 public:
  static constexpr int kMaxWindow = 64;
  void update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a);
  void on_rejoin() { reset(); }
  bool pending() const { return pending_; }

 private:
  void reset() {
    count_ = 0;
    pending_ = false;
  }
  std::array<double, kMaxWindow> x_{};
  std::array<double, kMaxWindow> lc_{};
  int head_ = 0;   // next slot
  int count_ = 0;  // samples in the window
  bool pending_ = false;
  double level_kN_ = 0.0;  // the still window's mean load cell when the step came
  double step_kN_ = 0.0;
  double onset_s_ = 0.0;
  int kept_ = 0;
};

}  // namespace bbw::faults
