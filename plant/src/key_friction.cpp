#include "bbw/plant/key_friction.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "bbw/model/maxwell_slip.hpp"

namespace bbw::plant {

KeyFriction::KeyFriction(const KeyFrictionParams& params) {
  PlantParams check;
  check.key_friction = params;
  check.validate();
  const auto m = static_cast<std::size_t>(params.elements);
  delta_rev_.resize(m);
  k_kN_per_rev_.resize(m);
  pos_rev_.assign(m, 0.0);
  // Thresholds: drawn from the structure seed (a property of the caliper).
  std::mt19937_64 rng(params.structure_seed);
  const bool clip = params.threshold_max_rev > 0.0;
  if (params.threshold_distribution == ThresholdDistribution::LogUniform) {
    std::uniform_real_distribution<double> draw(std::log(params.threshold_min_rev), std::log(params.threshold_max_rev));
    for (auto& d : delta_rev_) d = std::exp(draw(rng));
  } else {
    std::lognormal_distribution<double> draw(std::log(params.threshold_median_rev), params.threshold_log_sigma);
    for (auto& d : delta_rev_) {
      d = draw(rng);
      if (clip) d = std::clamp(d, std::max(params.threshold_min_rev, 1e-12), params.threshold_max_rev);
    }
  }
  std::sort(delta_rev_.begin(), delta_rev_.end());
  // Force shares K_i Delta_i proportional to Delta_i^p (times a seeded log-normal factor when
  // share_log_sigma > 0), normalised to the half-width.
  std::vector<double> weight(m);
  std::normal_distribution<double> unit(0.0, 1.0);
  for (std::size_t i = 0; i < m; ++i) {
    weight[i] = std::pow(delta_rev_[i], params.force_share_exponent);
    if (params.share_log_sigma > 0.0) weight[i] *= std::exp(params.share_log_sigma * unit(rng));
  }
  double sum = 0.0;
  for (double w : weight) sum += w;
  for (std::size_t i = 0; i < m; ++i) k_kN_per_rev_[i] = params.half_width_kN * (weight[i] / sum) / delta_rev_[i];
  initial_deflection_ = params.initial_deflection;
}

void KeyFriction::reset(double x_rev) {
  // Element i deflected by initial_deflection * Delta_i: its position lags x by that much.
  for (std::size_t i = 0; i < pos_rev_.size(); ++i) pos_rev_[i] = x_rev - initial_deflection_ * delta_rev_[i];
  force_kN_ = 0.0;
  for (std::size_t i = 0; i < pos_rev_.size(); ++i) force_kN_ += k_kN_per_rev_[i] * delta_rev_[i] * initial_deflection_;
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
