#include "bbw/plant/key_friction.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "bbw/calibration/maxwell_slip.hpp"

namespace bbw::plant {

KeyFriction::KeyFriction(const KeyFrictionParams& params) {
  PlantParams check;
  check.key_friction = params;
  check.validate();
  const auto m = static_cast<std::size_t>(params.elements);
  delta_rev_.resize(m);
  k_kN_per_rev_.resize(m);
  pos_rev_.assign(m, 0.0);
  // Thresholds: log-normal draws from the structure seed (a property of the caliper).
  std::mt19937_64 rng(params.structure_seed);
  std::lognormal_distribution<double> draw(std::log(params.threshold_median_rev),
                                           params.threshold_log_sigma);
  for (auto& d : delta_rev_) d = draw(rng);
  std::sort(delta_rev_.begin(), delta_rev_.end());
  // Force shares K_i Delta_i proportional to Delta_i^p, normalised to the half-width.
  double sum = 0.0;
  for (std::size_t i = 0; i < m; ++i) sum += std::pow(delta_rev_[i], params.force_share_exponent);
  for (std::size_t i = 0; i < m; ++i) {
    const double share = std::pow(delta_rev_[i], params.force_share_exponent) / sum;
    k_kN_per_rev_[i] = params.half_width_kN * share / delta_rev_[i];
  }
}

void KeyFriction::reset(double x_rev) {
  std::fill(pos_rev_.begin(), pos_rev_.end(), x_rev);
  force_kN_ = 0.0;
}

double KeyFriction::step(double x_rev) {
  force_kN_ = calibration::elements_step(x_rev, delta_rev_.data(), pos_rev_.data(), delta_rev_.size(),
                                         k_kN_per_rev_.data(), nullptr);
  return force_kN_;
}

double KeyFriction::half_width_kN() const {
  double h = 0.0;
  for (std::size_t i = 0; i < delta_rev_.size(); ++i) h += k_kN_per_rev_[i] * delta_rev_[i];
  return h;
}

}  // namespace bbw::plant
