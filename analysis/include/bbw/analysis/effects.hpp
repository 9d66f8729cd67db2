// Effect regressors of the residual analysis, as pure per-sample arithmetic so that the online
// calibrator can reuse them as optional model terms (issue 6, "back into the product").
// No allocation in the per-sample types; the batch helpers fill caller-sized vectors.
#pragma once

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

#include "bbw/model/maxwell_slip.hpp"

namespace bbw::analysis {

// Backlash: play operator of total width `width` (dead band of width/2 either side). The output
// stays until the input pushes it from one side of the band: out = clamp(out, x - w/2, x + w/2).
class PlayOperator {
 public:
  explicit PlayOperator(double width) : half_(0.5 * width) {
    if (!(width >= 0.0)) throw std::invalid_argument("PlayOperator: width must be >= 0");
  }
  void reset(double x) { out_ = x; started_ = true; }
  double step(double x) {
    if (!started_) reset(x);
    if (out_ < x - half_) out_ = x - half_;
    if (out_ > x + half_) out_ = x + half_;
    return out_;
  }

 private:
  double half_;
  double out_ = 0.0;
  bool started_ = false;
};

// First-order lag y' = (u - y) / tau, exact discretisation for a sample held over dt.
class FirstOrderLag {
 public:
  explicit FirstOrderLag(double tau_s) : tau_s_(tau_s) {
    if (!(tau_s > 0.0)) throw std::invalid_argument("FirstOrderLag: tau_s must be > 0");
  }
  void reset(double u) { y_ = u; started_ = true; }
  double step(double u, double dt_s) {
    if (!started_) reset(u);
    const double a = std::exp(-dt_s / tau_s_);
    y_ = a * y_ + (1.0 - a) * u;
    return y_;
  }

 private:
  double tau_s_;
  double y_ = 0.0;
  bool started_ = false;
};

// Creep regressor: the part of `u` that has not yet relaxed, u - lag_tau(u). A force that
// relaxes by a fraction beta with time constant tau reads beta * (this) less than the curve.
inline std::vector<double> creep_regressor(const std::vector<double>& u, double dt_s, double tau_s) {
  FirstOrderLag lag(tau_s);
  std::vector<double> out(u.size());
  for (std::size_t k = 0; k < u.size(); ++k) out[k] = u[k] - lag.step(u[k], dt_s);
  return out;
}

// Play operator over a whole signal.
inline std::vector<double> play(const std::vector<double>& x, double width) {
  PlayOperator p(width);
  std::vector<double> out(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) out[k] = p.step(x[k]);
  return out;
}

// x delayed by delay_s on a uniform grid (linear interpolation; held at the ends). A positive
// delay means the output at t is x(t - delay_s).
inline std::vector<double> delayed(const std::vector<double>& x, double dt_s, double delay_s) {
  const std::size_t n = x.size();
  std::vector<double> out(n);
  if (n == 0) return out;
  const double shift = delay_s / dt_s;
  for (std::size_t k = 0; k < n; ++k) {
    const double src = static_cast<double>(k) - shift;
    if (src <= 0.0) {
      out[k] = x.front();
    } else if (src >= static_cast<double>(n - 1)) {
      out[k] = x.back();
    } else {
      const auto i = static_cast<std::size_t>(src);
      const double f = src - static_cast<double>(i);
      out[k] = (1.0 - f) * x[i] + f * x[i + 1];
    }
  }
  return out;
}

// Maxwell-slip regressors n_i(t) for every sample, states streamed over every sample from zero
// deflection at the first sample. n is filled column-wise: n[i][k]. The friction force is
// sum_i K_i Delta_i n_i, so a fit on columns n_i returns K_i Delta_i >= 0.
inline void maxwell_slip_regressors(const std::vector<double>& x, const std::vector<double>& delta,
                                    std::vector<std::vector<double>>& n) {
  const std::size_t m = delta.size();
  n.assign(m, std::vector<double>(x.size()));
  std::vector<double> pos(m, x.empty() ? 0.0 : x.front());
  for (std::size_t k = 0; k < x.size(); ++k) {
    for (std::size_t i = 0; i < m; ++i) n[i][k] = calibration::element_step(x[k], delta[i], pos[i]);
  }
}

}  // namespace bbw::analysis
