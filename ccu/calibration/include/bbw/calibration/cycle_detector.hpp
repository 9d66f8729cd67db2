// Hysteresis-cycle start detection (eq. 6): a start is where x turns from falling to rising,
//   x(i) > x(i - n0) + margin  and  x(i - n0) < x(i - 2 n0) - margin.
// The detector fires on the first sample where the condition becomes true (edge-triggered);
// margin = 0 is the paper's rule, a margin of a few noise sigmas is robust mode's.
#pragma once

#include <cstdint>
#include <vector>

namespace bbw::calibration {

class CycleDetector {
 public:
  CycleDetector(int n0, double margin_rev);  // throws std::invalid_argument for n0 < 1

  // Feeds one position; returns true when a cycle start is detected at this sample.
  bool update(double x_rev);
  // Lowest position among the last 2 n0 + 1 samples (the turning point just passed).
  double recent_min_rev() const;
  void reset();

 private:
  std::vector<double> ring_;
  std::size_t head_ = 0;  // index of the newest sample
  std::uint64_t count_ = 0;
  int n0_;
  double margin_rev_;
  bool was_true_ = false;
};

}  // namespace bbw::calibration
