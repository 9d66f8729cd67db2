// Hysteresis-cycle start detection: a start is where x turns from falling to rising.
//
// margin = 0: the paper's rule (eq. 6), edge-triggered (fires on the first sample where
//   x(i) > x(i - n0)  and  x(i - n0) < x(i - 2 n0)  becomes true).
//   Near a slow, noisy minimum it can fire more than once; the calibrator's "at least L
//   samples since the last start" rule absorbs that.
// margin > 0: robust mode's turning-point detector with hysteresis: while falling it tracks the
//   lowest x; it fires when x rises more than `margin` above it, then tracks the highest x and
//   re-arms when x falls more than `margin` below that. Noise below the margin cannot fire it,
//   however slow the turn; the price is a detection delay of the time to rise by `margin`.
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
  bool falling_ = true;       // hysteresis detector state
  double extreme_rev_ = 0.0;  // running min (falling) or max (rising)
};

}  // namespace bbw::calibration
