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
  // Takes the end-of-line keys' whole stiffness (MonitorParams::step_friction_allowance; 0
  // without an end-of-line key model).
  explicit StepDetector(const MonitorParams& p);
  void update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a);
  void on_rejoin() { reset(); }
  bool pending() const { return pending_; }
  // The corner's actuator test in holds ran over the `samples` samples before this one (the
  // torque rule recognises it at the first sample after it). They leave the still window: the
  // pulse moves the rotor 0.1-0.7 mrev and back by a little less (up to 1 mrev net) and the clamp
  // force by a few N to tens of N, so the still samples on either side still show the level a
  // load-cell step leaves (kAcrossPulseSpans still spans apart at most). A step that came during
  // the pulse is judged here, at the sample after it, against the still samples before it
  // (kDuringPulseSpans apart, the loop may already be moving the rotor; at least kStepJumpShare
  // of it between two samples). Without this a test every 15 ms left a hold almost no still
  // window (issue 14, eleventh session).
  static constexpr double kAcrossPulseSpans = 2.0;
  static constexpr double kDuringPulseSpans = 3.0;
  static constexpr double kStepJumpShare = 0.5;
  void on_test_pulse(int samples, double time_s, const MonitorParams& p);

 private:
  void reset() {
    count_ = 0;
    pending_ = false;
  }
  // The still window's mean load cell, and the step it must be left by (step_kN and the keys'
  // allowance for the window's travel).
  bool still_level(const MonitorParams& p, double x_now, int skip, double across_pulse, double& level, double& step_kN) const;
  void begin_step(double level_kN, double step_kN, double time_s);
  std::array<double, kMaxWindow> x_{};
  std::array<double, kMaxWindow> lc_{};
  std::array<bool, kMaxWindow> pulse_{};  // the sample belonged to a test pulse
  // The sample's measured speed was beyond step_still_max_speed_rev_per_s: a drive stopped within
  // a sample (a seizure at 25 rev/s) stands within the still span from that sample on, while its
  // load cell still carries the speed's viscous term there (5 kN at 0.2 kN/(rev/s)).
  std::array<bool, kMaxWindow> fast_{};
  static bool fast(const MonitorParams& p, double speed_rev_per_s);
  double all_sticking_kN_per_rev_ = 0.0;  // the end-of-line keys' whole stiffness
  int head_ = 0;   // next slot
  int count_ = 0;  // samples in the window
  bool pending_ = false;
  double level_kN_ = 0.0;  // the still window's mean load cell when the step came
  double step_kN_ = 0.0;
  double onset_s_ = 0.0;
  int kept_ = 0;
};

}  // namespace bbw::faults
