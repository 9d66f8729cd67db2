// Maxwell-slip elements (eqs. 1-4): massless elasto-slip elements in parallel on input x.
// Pure arithmetic, no allocation: the caller owns the arrays.
#pragma once

#include <cmath>
#include <cstddef>

namespace bbw::calibration {

// Normalised deflection n_i of one element at input x, given its position x_i, and the
// element position after the sample (x_i stays when sticking, follows x at Delta_i when slipping).
// Reading chosen: the state update uses the current sample's deflection, so n_i is +/-1 exactly
// while slipping and the element position is x - sgn(d) Delta (eq. 2 with t+1 := t).
inline double element_step(double x_rev, double delta_rev, double& pos_rev) {
  const double d = x_rev - pos_rev;
  if (d >= delta_rev) {
    pos_rev = x_rev - delta_rev;
    return 1.0;
  }
  if (d <= -delta_rev) {
    pos_rev = x_rev + delta_rev;
    return -1.0;
  }
  return d / delta_rev;
}

// Backlash: one step of the play operator. `spindle_rev` (the state) is dragged along so that it
// stays within half the play of the resolver position; returns it.
inline double play_step(double& spindle_rev, double x_rev, double width_rev) {
  const double half = 0.5 * width_rev;
  if (spindle_rev < x_rev - half) spindle_rev = x_rev - half;
  if (spindle_rev > x_rev + half) spindle_rev = x_rev + half;
  return spindle_rev;
}

// Load-dependent key friction: the factor 1 + g max(F, 0) / F_ref on the Maxwell-slip friction
// at clamp force F (kN).
inline double load_friction_scale(double gain, double reference_kN, double force_kN) {
  return 1.0 + gain * (force_kN > 0.0 ? force_kN : 0.0) / reference_kN;
}

// Load-cell thermal offset k (T - T_ref), kN.
inline double load_cell_offset_kN(double kN_per_C, double reference_C, double temperature_C) {
  return kN_per_C * (temperature_C - reference_C);
}

// Steps all M elements at x; writes n_i into n_out (may be null). Returns sum K_i Delta_i n_i
// when k is non-null, else 0.
inline double elements_step(double x_rev, const double* delta_rev, double* pos_rev, std::size_t m,
                            const double* k_kN_per_rev, double* n_out) {
  double f = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    const double n = element_step(x_rev, delta_rev[i], pos_rev[i]);
    if (n_out) n_out[i] = n;
    if (k_kN_per_rev) f += k_kN_per_rev[i] * delta_rev[i] * n;
  }
  return f;
}

// When the element states are known whatever the friction's initial deflection: once x has
// moved 2 Delta_max from its running lowest or highest position, every element (the real
// one and a model started relaxed alike) has been dragged to x -/+ Delta_i. Shared by the
// online calibrator (cycle starts before it are ignored) and ./bbw analyze (samples before it
// are not scored).
class StatesKnown {
 public:
  explicit StatesKnown(double delta_max) : two_delta_(2.0 * delta_max) {}
  // Feeds one position; true from the sample at which the states are known on.
  bool update(double x) {
    if (known_) return true;
    if (!started_) {
      low_ = high_ = x;
      started_ = true;
    }
    low_ = x < low_ ? x : low_;
    high_ = x > high_ ? x : high_;
    known_ = x - low_ >= two_delta_ || high_ - x >= two_delta_;
    return known_;
  }
  bool known() const { return known_; }

 private:
  double two_delta_;
  double low_ = 0.0, high_ = 0.0;
  bool started_ = false;
  bool known_ = false;
};

// Index of the first sample at which the states are known (n when never).
inline std::size_t first_known_sample(const double* x, std::size_t n, double delta_max) {
  StatesKnown s(delta_max);
  for (std::size_t k = 0; k < n; ++k) {
    if (s.update(x[k])) return k;
  }
  return n;
}

// Thresholds: even Delta_i = (i / M) Delta_max, or geometric Delta_M = Delta_max,
// Delta_{i-1} = ratio * Delta_i.
inline void thresholds(std::size_t m, double delta_max_rev, bool geometric, double ratio, double* out) {
  for (std::size_t i = 0; i < m; ++i) {
    if (geometric) {
      out[i] = delta_max_rev * std::pow(ratio, static_cast<double>(m - 1 - i));
    } else {
      out[i] = delta_max_rev * static_cast<double>(i + 1) / static_cast<double>(m);
    }
  }
}

}  // namespace bbw::calibration
