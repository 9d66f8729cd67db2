// A noisy load cell: in a window of the residual's sample-to-sample changes, the share larger
// than noise_step_kN (a single step, e.g. a bias or a resolver jump, is one sample, not noise)
// reaching noise_min_fraction (LoadCellNoisy). Memory sized at compile time (kMaxNoiseWindow).
#pragma once

#include <array>
#include <cstdint>

#include "bbw/faults/detectors/detector.hpp"

namespace bbw::faults {

inline constexpr int kMaxNoiseWindow = 256;

class NoiseDetector {
 public:
  void update(double residual_kN, double t, const MonitorParams& p, DiagnosisArbiter& a);
  void on_rejoin() { have_prev_residual_ = false; }
  double fraction() const { return fraction_; }

 private:
  bool have_prev_residual_ = false;
  double prev_residual_kN_ = 0.0;
  std::array<std::uint8_t, kMaxNoiseWindow> big_{};
  int count_ = 0;
  int head_ = 0;
  int big_count_ = 0;
  double fraction_ = 0.0;  // share of big steps in the window
};

}  // namespace bbw::faults
