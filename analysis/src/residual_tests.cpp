#include "bbw/analysis/residual_tests.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace bbw::analysis {

double white_noise_sigma(const std::vector<double>& r) {
  if (r.size() < 5) return 0.0;
  std::vector<double> d2(r.size() - 2);
  for (std::size_t k = 1; k + 1 < r.size(); ++k) d2[k - 1] = r[k + 1] - 2.0 * r[k] + r[k - 1];
  std::vector<double> a(d2.size());
  std::nth_element(d2.begin(), d2.begin() + static_cast<std::ptrdiff_t>(d2.size() / 2), d2.end());
  const double med = d2[d2.size() / 2];
  for (std::size_t k = 0; k < d2.size(); ++k) a[k] = std::abs(d2[k] - med);
  std::nth_element(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(a.size() / 2), a.end());
  return 1.4826 * a[a.size() / 2] / std::sqrt(6.0);
}

double chi2_upper_1pct(double k) {
  const double z = 2.326347874;  // standard normal 99 % quantile
  const double h = 2.0 / (9.0 * k);
  const double c = 1.0 - h + z * std::sqrt(h);
  return k * c * c * c;
}

WhitenessTest whiteness(const std::vector<double>& r, int lags) {
  WhitenessTest t;
  t.lags = lags;
  const std::size_t n = r.size();
  if (n < static_cast<std::size_t>(lags) + 10) return t;
  const double mean = std::accumulate(r.begin(), r.end(), 0.0) / static_cast<double>(n);
  double c0 = 0.0;
  for (double v : r) c0 += (v - mean) * (v - mean);
  if (c0 <= 0.0) return t;
  double q = 0.0;
  for (int l = 1; l <= lags; ++l) {
    double c = 0.0;
    for (std::size_t k = static_cast<std::size_t>(l); k < n; ++k) c += (r[k] - mean) * (r[k - static_cast<std::size_t>(l)] - mean);
    const double rho = c / c0;
    if (l == 1) t.lag1_autocorrelation = rho;
    q += rho * rho / static_cast<double>(n - static_cast<std::size_t>(l));
  }
  t.ljung_box_q = static_cast<double>(n) * (static_cast<double>(n) + 2.0) * q;
  t.critical_q = chi2_upper_1pct(lags);
  t.significant = t.ljung_box_q > t.critical_q;
  const double var = c0 / static_cast<double>(n);
  t.noise_rms = white_noise_sigma(r);
  t.structured_rms = std::sqrt(std::max(0.0, var - t.noise_rms * t.noise_rms));
  return t;
}

DependenceTest dependence(const std::vector<double>& r, const std::vector<double>& by, int bins,
                          const std::string& name) {
  DependenceTest t;
  t.against = name;
  const std::size_t n = std::min(r.size(), by.size());
  if (n < static_cast<std::size_t>(bins) * 5) return t;
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return by[a] < by[b]; });
  const double mean = std::accumulate(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(n), 0.0) / static_cast<double>(n);
  double total = 0.0;
  for (std::size_t k = 0; k < n; ++k) total += (r[k] - mean) * (r[k] - mean);
  if (total <= 0.0) return t;
  double between = 0.0;
  int used_bins = 0;
  for (int b = 0; b < bins; ++b) {
    const std::size_t lo = n * static_cast<std::size_t>(b) / static_cast<std::size_t>(bins);
    const std::size_t hi = n * static_cast<std::size_t>(b + 1) / static_cast<std::size_t>(bins);
    if (hi <= lo) continue;
    double s = 0.0;
    for (std::size_t k = lo; k < hi; ++k) s += r[order[k]];
    const double m = s / static_cast<double>(hi - lo);
    between += static_cast<double>(hi - lo) * (m - mean) * (m - mean);
    ++used_bins;
  }
  t.eta2 = between / total;
  const double df1 = std::max(1, used_bins - 1);
  const double df2 = static_cast<double>(n) - used_bins;
  t.f_statistic = (t.eta2 / df1) / (std::max(1e-300, 1.0 - t.eta2) / df2);
  t.f_critical = chi2_upper_1pct(df1) / df1;
  t.significant = t.f_statistic > t.f_critical;
  return t;
}

}  // namespace bbw::analysis
