// A noisy load cell: in a window of the residual's sample-to-sample changes, the share larger
// than noise_step_kN (a single step, e.g. a bias or a resolver jump, is one sample, not noise)
// reaching noise_min_fraction (LoadCellNoisy). A change the model itself made in that sample
// (model_kN, what the residual is taken against) is allowed on top: where the load cell follows
// the model late (a 5 ms sensor delay at an ABS reversal, the key friction flipping by 2 kN
// within 5 ms) the residual steps twice, once with the model and once with the load cell.
// The step threshold rises with the corner's own learnt healthy level (noise_learned_factor).
// Memory sized at compile time (kMaxNoiseWindow).
#pragma once

#include <array>
#include <cstdint>

#include "bbw/faults/detectors/detector.hpp"

namespace bbw::faults {

inline constexpr int kMaxNoiseWindow = 256;

class NoiseDetector {
 public:
  void update(double residual_kN, double model_kN, double t, const MonitorParams& p, DiagnosisArbiter& a);
  // Without a residual (the resolver is diagnosed): the load cell's first difference F[k] - F[k-1];
  // its change, the second difference, counts as big beyond noise_second_difference_kN, or
  // beyond the corner's own learnt level (from its residual before, and from these differences).
  // Not `before_learnt`: counted only once that level is learnt (noise_second_difference_learn_s)
  // or the residual's is.
  void update_load_cell_difference(double difference_kN, double t, const MonitorParams& p, DiagnosisArbiter& a,
                                   bool before_learnt = true);
  void on_rejoin() { have_prev_residual_ = have_prev_difference_ = false; }
  double fraction() const { return fraction_; }

 private:
  bool have_prev_residual_ = false;
  double prev_residual_kN_ = 0.0;
  double prev_model_kN_ = 0.0;
  bool have_prev_difference_ = false;
  double prev_difference_kN_ = 0.0;
  void count(bool big, double t, const MonitorParams& p, DiagnosisArbiter& a);
  std::array<std::uint8_t, kMaxNoiseWindow> big_{};
  int count_ = 0;
  int head_ = 0;
  int big_count_ = 0;
  double fraction_ = 0.0;  // share of big steps in the window
  // A healthy level learnt while the window is below a finding: the plain mean until the time
  // constant is reached, then exponential; it counts once a whole time constant was learnt (a
  // burst early in the run must not be learnt as the healthy level before it is seen).
  struct LearntLevel {
    double mean_kN = 0.0;  // learnt from 0: the fixed step alone until it has grown
    bool have_time = false;
    double learnt_s = 0.0;  // time learnt so far
    double time_s = 0.0;
    void learn(double value_kN, double t, bool quiet, double time_constant_s);
    bool learnt(double time_constant_s) const { return learnt_s >= time_constant_s; }
  };
  LearntLevel step_level_;    // the residual's |first difference|
  LearntLevel second_level_;  // the load cell's |second difference| (without a residual)
};

}  // namespace bbw::faults
