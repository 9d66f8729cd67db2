// Load-cell step while the actuator moves (issue 14, twelfth session). The still step rule
// (StepDetector) needs the rotor at rest; before the first fit a bias injected during an apply
// or a release waited for the end-of-line band, hundreds of milliseconds (tune_bias run 153: a
// -2.2 kN bias at 1 rev/s, named 476 ms later). Moving, the load cell against the caliper's
// end-of-line curve, q = load cell - eol(position, temperature), changes from one sample to the
// next by what the curve does not hold:
//   - the key friction, by at most the sum of its elements' stiffnesses times the travel (every
//     element sticking: right after a reversal), whatever its state;
//   - speed effects (viscous friction, a load cell's delay): smooth, so a straight line through
//     the last step.moving.window_samples values carries them (its slope is the trend, and
//     kSpreads x the values' spread about it is allowed), and a speed change is allowed
//     step.moving.speed_kN_per_rev_per_s per rev/s beyond it;
//   - a drive's backlash or a delayed load cell, for which the curve's own largest change in the
//     window is allowed besides.
// A change beyond step.step_kN + those, against a quiet window (the spread about the line at most
// step.moving.quiet_fraction x step_kN: a noise burst makes no step), that stays
// beyond step.keep_fraction of itself for step.confirm_samples more is a load-cell offset. Only
// beyond the end-of-line curve's contact point at the measured temperature (pads on the disc),
// never across a position step the measured speed does not explain (a resolver jump), and only
// with an end-of-line curve and key-friction model. The key friction's bound follows the travel
// since the last reversal (a back-motion beyond kReversalRev; one below it may have turned every
// element by as much, kReversalRev x their whole stiffness, which is allowed besides): on a
// caliper with stiff keys every element sticks for a few mrev after a reversal (up to 0.75 kN per
// 1 ms sample at 2 rev/s), and none once the travel passes twice the largest threshold.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "bbw/faults/detectors/detector.hpp"
#include "bbw/plant/clamp_curve.hpp"

namespace bbw::faults {

class MovingStepDetector {
 public:
  static constexpr int kMaxWindow = 64;
  static constexpr double kReversalRev = 1e-4;  // 5 resolver quanta
  static constexpr double kSpreads = 4.0;       // the window's own spread about its line, allowed besides
  explicit MovingStepDetector(const MonitorParams& p);
  void update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a);
  void on_rejoin() {
    reset();
    direction_ = 0;  // the travel since the last reversal is no longer known
  }
  bool pending() const { return pending_; }
  // The end-of-line key friction's largest rate of change (kN/rev) `travel_rev` after a reversal:
  // the elements still sticking (an element goes from one side of its threshold to the other over
  // twice its threshold), all of them right at the reversal.
  double friction_stiffness_kN_per_rev(double travel_rev) const;

 private:
  void reset() {
    restart_window();
    pending_ = false;
  }
  void restart_window() {
    count_ = 0;
    sum_q_ = sum_kq_ = 0.0;
  }
  std::optional<plant::ClampCurve> eol_;
  // The elements' full-swing travels (twice their thresholds), ascending, and the sum of the
  // stiffnesses of the elements from each one on.
  std::vector<double> swing_rev_;
  std::vector<double> stiffness_from_kN_per_rev_;
  double backlash_rev_ = 0.0;
  double all_sticking_kN_per_rev_ = 0.0;  // every element's stiffness: right after a reversal
  // The travel since the last reversal: the direction of motion and the running extreme.
  int direction_ = 0;
  double extreme_rev_ = 0.0;
  double turn_rev_ = 0.0;  // where the last reversal was
  struct Sample {
    double q_kN, eol_kN, v_rev_per_s, deol_kN;
  };
  std::array<Sample, kMaxWindow> w_{};
  int head_ = 0;
  int count_ = 0;
  // Over the window's last step.moving.window_samples samples: the sum of q and of k q, k the
  // samples back (1: the newest).
  double sum_q_ = 0.0;
  double sum_kq_ = 0.0;
  bool pending_ = false;
  double level_kN_ = 0.0;  // q the window predicts at the step's sample
  double trend_kN_ = 0.0;  // the line's slope, per sample
  double step_kN_ = 0.0;
  double onset_s_ = 0.0;
  int kept_ = 0;
};

}  // namespace bbw::faults
