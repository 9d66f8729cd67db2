#include "bbw/calibration/fusion.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace bbw::calibration {

void FusionParams::validate() const {
  if (!(load_cell_noise_kN > 0.0)) throw std::invalid_argument("fusion: load_cell_noise_kN must be > 0");
  if (!(time_constant_s > 0.0)) throw std::invalid_argument("fusion: time_constant_s must be > 0");
  if (!(initial_curve_mse_kN2 >= 0.0)) throw std::invalid_argument("fusion: initial_curve_mse_kN2 must be >= 0");
}

EstimateFusion::EstimateFusion(const FusionParams& params) : p_((params.validate(), params)) { reset(); }

void EstimateFusion::reset() {
  mse_kN2_ = p_.initial_curve_mse_kN2;
  weight_ = 0.0;
}

double EstimateFusion::curve_rms_error_kN() const { return std::sqrt(mse_kN2_); }

double EstimateFusion::update(const Estimate& e, double dt_s) {
  if (!e.valid || !e.calibrated || !std::isfinite(e.curve_force_kN)) {
    weight_ = 0.0;
    return e.force_kN;
  }
  const double r = e.force_kN - e.curve_force_kN;
  const double a = dt_s > 0.0 ? 1.0 - std::exp(-dt_s / p_.time_constant_s) : 0.0;
  const double var_lc = p_.load_cell_noise_kN * p_.load_cell_noise_kN;
  mse_kN2_ += a * (std::max(0.0, r * r - var_lc) - mse_kN2_);
  weight_ = var_lc / (var_lc + mse_kN2_);
  return e.force_kN + weight_ * (e.curve_force_kN - e.force_kN);
}

}  // namespace bbw::calibration
