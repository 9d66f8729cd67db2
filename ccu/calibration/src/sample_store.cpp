#include "bbw/calibration/sample_store.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace bbw::calibration {

SampleStore::SampleStore(int capacity_L, int row_width_M, double x_range_rev, double f_range_kN,
                         DropRule rule)
    : capacity_(static_cast<std::size_t>(capacity_L)),
      width_(static_cast<std::size_t>(row_width_M)),
      rule_(rule) {
  if (capacity_L < 2) throw std::invalid_argument("samples_L must be >= 2, got " + std::to_string(capacity_L));
  if (row_width_M < 0) throw std::invalid_argument("row width must be >= 0");
  if (!(x_range_rev > 0.0) || !(f_range_kN > 0.0)) {
    throw std::invalid_argument("distance rule ranges must be > 0 (x_max_rev > x_min_rev, f_max_kN > f_min_kN)");
  }
  inv_x2_ = 1.0 / (x_range_rev * x_range_rev);
  inv_f2_ = 1.0 / (f_range_kN * f_range_kN);
  x_.assign(capacity_ + 1, 0.0);
  f_.assign(capacity_ + 1, 0.0);
  n_.assign((capacity_ + 1) * std::max<std::size_t>(width_, 1), 0.0f);
  order_.assign(capacity_ + 1, 0);
  d2_.assign(capacity_, 0.0);
  clear();
}

void SampleStore::clear() {
  for (std::size_t k = 0; k < order_.size(); ++k) order_[k] = static_cast<std::uint32_t>(k);
  count_ = 0;
}

double SampleStore::dist2(std::size_t a, std::size_t b) const {
  const double dx = x_[order_[b]] - x_[order_[a]];
  const double df = f_[order_[b]] - f_[order_[a]];
  return dx * dx * inv_x2_ + df * df * inv_f2_;
}

void SampleStore::write(std::size_t phys, double x, double f, const double* n_row) {
  x_[phys] = x;
  f_[phys] = f;
  if (n_row) {
    float* dst = &n_[phys * width_];
    for (std::size_t i = 0; i < width_; ++i) dst[i] = static_cast<float>(n_row[i]);
  }
}

void SampleStore::rescan_settled_min() {
  // Two passes: the smallest value, then its first index (the first-index-on-ties rule). The
  // value pass keeps eight independent minima so that it is not one long chain of dependent
  // min instructions (at L = 128 that chain was half the calibrator's per-sample time).
  const std::size_t n = capacity_ - 1;
  const double* d = d2_.data();
  double acc[8];
  for (double& a : acc) a = d[0];
  std::size_t k = 1;
  for (; k + 8 <= n; k += 8) {
    for (std::size_t u = 0; u < 8; ++u) acc[u] = d[k + u] < acc[u] ? d[k + u] : acc[u];
  }
  for (; k < n; ++k) acc[0] = d[k] < acc[0] ? d[k] : acc[0];
  double m = acc[0];
  for (std::size_t u = 1; u < 8; ++u) m = acc[u] < m ? acc[u] : m;
  std::size_t j = 0;
  while (d[j] != m) ++j;
  settled_min_ = j;
}

void SampleStore::add(double x_rev, double f_kN, const double* n_row) {
  if (count_ < capacity_) {
    write(order_[count_], x_rev, f_kN, n_row);
    if (count_ > 0) d2_[count_ - 1] = dist2(count_ - 1, count_);
    ++count_;
    if (count_ == capacity_) rescan_settled_min();
    return;
  }
  // Store full: the new sample takes logical slot L (0-based), the spare one.
  const std::size_t L = capacity_;
  write(order_[L], x_rev, f_kN, n_row);
  d2_[L - 1] = dist2(L - 1, L);
  // argmin over all L pairs, first index on ties: the new pair wins only if strictly smaller.
  const std::size_t j = d2_[L - 1] < d2_[settled_min_] ? L - 1 : settled_min_;
  ++dropped_;
  if (j == L - 1) return;  // the new sample is closest to its predecessor: not recorded
  std::size_t drop = (rule_ == DropRule::DropJ) ? j : j + 1;
  const std::uint32_t freed = order_[drop];
  for (std::size_t k = drop; k < L; ++k) order_[k] = order_[k + 1];
  order_[L] = freed;
  for (std::size_t k = drop; k + 1 < L; ++k) d2_[k] = d2_[k + 1];
  if (drop > 0) d2_[drop - 1] = dist2(drop - 1, drop);
  rescan_settled_min();
}

double SampleStore::min_x_rev() const {
  double m = x_rev(0);
  for (std::size_t k = 1; k < count_; ++k) m = std::min(m, x_rev(k));
  return m;
}

double SampleStore::max_x_rev() const {
  double m = x_rev(0);
  for (std::size_t k = 1; k < count_; ++k) m = std::max(m, x_rev(k));
  return m;
}

std::size_t SampleStore::bytes() const {
  return sizeof(*this) + (x_.capacity() + f_.capacity() + d2_.capacity()) * sizeof(double) +
         n_.capacity() * sizeof(float) +
         order_.capacity() * sizeof(std::uint32_t);
}

}  // namespace bbw::calibration
