// Key/keyway pre-sliding friction: a generalised Maxwell-slip model with unevenly spread
// (log-normal, seeded) thresholds and smoothly distributed stiffnesses. Richer than the
// calibrator's model on purpose, so that the calibrator is never fitted to its own generator.
#pragma once

#include <cstddef>
#include <vector>

#include "bbw/plant/params.hpp"

namespace bbw::plant {

class KeyFriction {
 public:
  explicit KeyFriction(const KeyFrictionParams& params);  // throws std::invalid_argument

  // Input at x, every element at the params' initial_deflection (0: relaxed).
  void reset(double x_rev);
  // Moves the input to x; returns the friction force sum K_i Delta_i n_i (kN). No allocation.
  double step(double x_rev);
  double force_kN() const { return force_kN_; }

  std::size_t elements() const { return delta_rev_.size(); }
  const std::vector<double>& thresholds_rev() const { return delta_rev_; }
  const std::vector<double>& stiffness_kN_per_rev() const { return k_kN_per_rev_; }
  double half_width_kN() const;  // sum K_i Delta_i

 private:
  std::vector<double> delta_rev_;
  std::vector<double> k_kN_per_rev_;
  std::vector<double> pos_rev_;
  double force_kN_ = 0.0;
  double initial_deflection_ = 0.0;
};

}  // namespace bbw::plant
