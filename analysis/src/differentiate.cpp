#include "bbw/analysis/differentiate.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bbw::analysis {

namespace {

std::size_t usable_half(std::size_t k, std::size_t n, std::size_t h) {
  return std::min({h, k, n - 1 - k});
}

double first_at(const std::vector<double>& x, std::size_t k, std::size_t h, double dt_s) {
  double num = 0.0;
  double den = 0.0;
  for (std::size_t j = 1; j <= h; ++j) {
    const double w = static_cast<double>(j);
    num += w * (x[k + j] - x[k - j]);
    den += 2.0 * w * w;
  }
  return num / (den * dt_s);
}

double second_at(const std::vector<double>& x, std::size_t k, std::size_t h, double dt_s) {
  // Quadratic coefficient a2 = sum (j^2 - m) y_j / sum (j^2 - m)^2, m = mean of j^2 over the window.
  const double nwin = static_cast<double>(2 * h + 1);
  double s2 = 0.0;
  for (std::size_t j = 1; j <= h; ++j) s2 += 2.0 * static_cast<double>(j * j);
  const double m = s2 / nwin;
  double num = -m * x[k];
  double den = m * m;
  for (std::size_t j = 1; j <= h; ++j) {
    const double c = static_cast<double>(j * j) - m;
    num += c * (x[k + j] + x[k - j]);
    den += 2.0 * c * c;
  }
  return 2.0 * num / (den * dt_s * dt_s);
}

template <typename F>
std::vector<double> apply(const std::vector<double>& x, std::size_t h, F at) {
  const std::size_t n = x.size();
  std::vector<double> out(n, 0.0);
  if (n < 3) return out;
  for (std::size_t k = 1; k + 1 < n; ++k) out[k] = at(k, usable_half(k, n, h));
  out[0] = out[1];
  out[n - 1] = out[n - 2];
  return out;
}

}  // namespace

std::size_t half_width_for(double window_s, double dt_s) {
  if (!(dt_s > 0.0)) throw std::invalid_argument("half_width_for: dt_s must be > 0");
  const double h = std::round(0.5 * window_s / dt_s);
  return h < 1.0 ? 1 : static_cast<std::size_t>(h);
}

std::vector<double> sg_first_derivative(const std::vector<double>& x, double dt_s, std::size_t half_width) {
  return apply(x, half_width, [&](std::size_t k, std::size_t h) { return first_at(x, k, h, dt_s); });
}

std::vector<double> sg_second_derivative(const std::vector<double>& x, double dt_s, std::size_t half_width) {
  return apply(x, half_width, [&](std::size_t k, std::size_t h) { return second_at(x, k, h, dt_s); });
}

}  // namespace bbw::analysis
