// Gross outliers (AnalysisResult::gross_outliers): replaced by the channel's previous good value.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "bbw/analysis/analysis.hpp"

namespace bbw::analysis {

namespace {

std::size_t reject_in(std::vector<double>& v, const std::string& name, std::vector<std::string>* where) {
  if (v.size() < 20) return 0;
  std::vector<double> sorted;
  sorted.reserve(v.size());
  for (double x : v)
    if (std::isfinite(x)) sorted.push_back(x);
  if (sorted.size() < 20) return 0;
  const auto at = [&](double q) {
    const auto i = static_cast<std::ptrdiff_t>(q * static_cast<double>(sorted.size() - 1));
    std::nth_element(sorted.begin(), sorted.begin() + i, sorted.end());
    return sorted[static_cast<std::size_t>(i)];
  };
  const double lo = at(0.005), hi = at(0.995);
  const double span = std::max(hi - lo, 1e-12 * std::max(std::abs(lo), std::abs(hi)));
  const double min_ok = lo - 10.0 * span, max_ok = hi + 10.0 * span;
  std::size_t count = 0;
  double last_good = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (v[k] >= min_ok && v[k] <= max_ok) {
      last_good = v[k];
      continue;
    }
    ++count;
    if (where && where->size() < 10) where->push_back(name + "@" + std::to_string(k));
    if (std::isfinite(last_good)) {
      v[k] = last_good;
    } else {  // at the start: the next good value
      std::size_t j = k + 1;
      while (j < v.size() && !(v[j] >= min_ok && v[j] <= max_ok)) ++j;
      v[k] = j < v.size() ? v[j] : 0.5 * (lo + hi);
    }
  }
  return count;
}

}  // namespace

std::size_t reject_gross_outliers(Recording& rec, std::vector<std::string>* where) {
  std::size_t n = reject_in(rec.position, "position", where);
  n += reject_in(rec.force, "force", where);
  n += reject_in(rec.truth, "truth", where);
  n += reject_in(rec.temperature, "temperature", where);
  n += reject_in(rec.velocity, "velocity", where);
  n += reject_in(rec.acceleration, "acceleration", where);
  for (auto& ch : rec.channels) n += reject_in(ch.values, "channel:" + ch.name, where);
  return n;
}

}  // namespace bbw::analysis
