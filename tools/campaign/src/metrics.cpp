#include "metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace bbw::campaign {

namespace {

// P(X <= k) for X ~ Binomial(n, p), summed in log space.
double binomial_cdf(long long k, long long n, double p) {
  if (k < 0) return 0.0;
  if (k >= n) return 1.0;
  if (p <= 0.0) return 1.0;
  if (p >= 1.0) return 0.0;
  const double lp = std::log(p), lq = std::log1p(-p);
  double sum = 0.0;
  for (long long i = 0; i <= k; ++i) {
    const double lc = std::lgamma(static_cast<double>(n) + 1.0) - std::lgamma(static_cast<double>(i) + 1.0) -
                      std::lgamma(static_cast<double>(n - i) + 1.0);
    sum += std::exp(lc + static_cast<double>(i) * lp + static_cast<double>(n - i) * lq);
  }
  return std::min(1.0, sum);
}

// The p where f(p) (decreasing in p) crosses `target`, by bisection on [0, 1].
template <class F>
double solve_decreasing(F f, double target) {
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (f(mid) > target) lo = mid;
    else hi = mid;
  }
  return 0.5 * (lo + hi);
}

void check(long long k, long long n) {
  if (n <= 0 || k < 0 || k > n) throw std::invalid_argument("a proportion needs 0 <= k <= n and n > 0");
}

}  // namespace

Interval wilson95(long long k, long long n) {
  check(k, n);
  const double z = 1.959963984540054, nn = static_cast<double>(n), p = static_cast<double>(k) / nn;
  const double centre = (p + z * z / (2.0 * nn)) / (1.0 + z * z / nn);
  const double half = z * std::sqrt(p * (1.0 - p) / nn + z * z / (4.0 * nn * nn)) / (1.0 + z * z / nn);
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

Interval clopper_pearson95(long long k, long long n) {
  check(k, n);
  Interval r;
  // Lower: P(X >= k | p) = 0.025, i.e. P(X <= k - 1 | p) = 0.975. Upper: P(X <= k | p) = 0.025.
  r.lo = k == 0 ? 0.0 : solve_decreasing([&](double p) { return binomial_cdf(k - 1, n, p); }, 0.975);
  r.hi = k == n ? 1.0 : solve_decreasing([&](double p) { return binomial_cdf(k, n, p); }, 0.025);
  return r;
}

double poisson_upper95(long long k) {
  if (k < 0) throw std::invalid_argument("an event count cannot be negative");
  auto cdf = [&](double mu) {
    double term = std::exp(-mu), sum = term;
    for (long long i = 1; i <= k; ++i) {
      term *= mu / static_cast<double>(i);
      sum += term;
    }
    return sum;
  };
  double lo = 0.0, hi = 10.0 + 3.0 * static_cast<double>(k);
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (cdf(mid) > 0.05) lo = mid;
    else hi = mid;
  }
  return 0.5 * (lo + hi);
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const double pos = std::clamp(p, 0.0, 1.0) * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(std::floor(pos));
  const std::size_t j = std::min(i + 1, v.size() - 1);
  return v[i] + (v[j] - v[i]) * (pos - static_cast<double>(i));
}

}  // namespace bbw::campaign
