// Fusing the two clamp-force estimates the calibrator gives: the friction-compensated load cell
// (f_hat: unbiased once calibrated, load-cell noise sigma_lc) and the curve from position (no
// load-cell noise, but biased wherever the cubic is off: between fits, at temperatures it has
// not seen, past its range).
//
// Inverse-variance weighting with the curve's error learned online from the disagreement
// r = f_hat - curve: E[r^2] = sigma_lc^2 + E[e_curve^2] when the two errors are independent, so
// an exponentially weighted mean of r^2 minus sigma_lc^2 estimates the curve's mean-square
// error, bias included. fused = f_hat + w (curve - f_hat), w = sigma_lc^2 / (sigma_lc^2 + mse).
// A curve that is off by 1 kN gets w ~ 0.001; a curve as good as the load cell gets w ~ 0.5.
// Pure, O(1), no allocation.
#pragma once

#include "bbw/calibration/calibrator.hpp"

namespace bbw::calibration {

struct FusionParams {
  double load_cell_noise_kN = 0.03;  // sigma_lc
  double time_constant_s = 2.0;      // memory of the curve's mean-square error
  double initial_curve_mse_kN2 = 1.0;  // before any disagreement has been seen: distrust the curve
  void validate() const;             // throws std::invalid_argument naming the field
};

class EstimateFusion {
 public:
  explicit EstimateFusion(const FusionParams& params);

  // One estimate in (dt_s since the previous call); returns the fused clamp force. Before the
  // calibrator's first fit, or for an invalid estimate, returns f_hat unchanged (NaN stays NaN).
  double update(const Estimate& e, double dt_s);

  double curve_weight() const { return weight_; }
  double curve_rms_error_kN() const;  // sqrt of the learned mean-square error
  void reset();

 private:
  FusionParams p_;
  double mse_kN2_;
  double weight_ = 0.0;
};

}  // namespace bbw::calibration
