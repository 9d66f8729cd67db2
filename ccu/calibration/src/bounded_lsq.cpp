#include "bbw/calibration/bounded_lsq.hpp"

#include <cmath>
#include <cstddef>
#include <stdexcept>

namespace bbw::calibration {

BoundedLeastSquares::BoundedLeastSquares(int max_params) : max_(max_params) {
  if (max_params < 1) throw std::invalid_argument("BoundedLeastSquares: max_params must be >= 1");
  const auto m = static_cast<std::size_t>(max_params);
  l_.assign(m * (m + 1) / 2, 0.0);  // packed lower triangle
  rhs_.assign(m, 0.0);
  idx_.assign(m, 0);
  passive_.assign(m, 0);
  z_.assign(m, 0.0);
  w_.assign(m, 0.0);
}

std::size_t BoundedLeastSquares::bytes() const {
  return sizeof(*this) + (l_.capacity() + rhs_.capacity() + z_.capacity() + w_.capacity()) * sizeof(double) +
         idx_.capacity() * sizeof(int) + passive_.capacity();
}

// Solves G_PP z_P = h_P for the passive set; z is zero elsewhere.
bool BoundedLeastSquares::solve_subset(const double* G, const double* h, int n, int ld, double* z) {
  int p = 0;
  for (int j = 0; j < n; ++j) {
    if (passive_[static_cast<std::size_t>(j)]) idx_[static_cast<std::size_t>(p++)] = j;
    z[j] = 0.0;
  }
  if (p == 0) return true;
  // Cholesky: L L' = G_PP, the lower triangle packed by rows in l_ (row r starts at r (r + 1) / 2).
  double* l = l_.data();
  auto row = [l](int r) { return l + static_cast<std::ptrdiff_t>(r) * (r + 1) / 2; };
  for (int r = 0; r < p; ++r) {
    double* lr = row(r);
    for (int c = 0; c <= r; ++c) {
      const double* lc = row(c);
      double s = G[idx_[static_cast<std::size_t>(r)] * ld + idx_[static_cast<std::size_t>(c)]];
      for (int k = 0; k < c; ++k) s -= lr[k] * lc[k];
      if (r == c) {
        if (!(s > 0.0) || !std::isfinite(s)) return false;
        lr[r] = std::sqrt(s);
      } else {
        lr[c] = s / lc[c];
      }
    }
  }
  for (int r = 0; r < p; ++r) {
    const double* lr = row(r);
    double s = h[idx_[static_cast<std::size_t>(r)]];
    for (int k = 0; k < r; ++k) s -= lr[k] * rhs_[static_cast<std::size_t>(k)];
    rhs_[static_cast<std::size_t>(r)] = s / lr[r];
  }
  for (int r = p - 1; r >= 0; --r) {
    double s = rhs_[static_cast<std::size_t>(r)];
    for (int k = r + 1; k < p; ++k) s -= row(k)[r] * rhs_[static_cast<std::size_t>(k)];
    rhs_[static_cast<std::size_t>(r)] = s / row(r)[r];
  }
  for (int r = 0; r < p; ++r) z[idx_[static_cast<std::size_t>(r)]] = rhs_[static_cast<std::size_t>(r)];
  return true;
}

bool BoundedLeastSquares::solve_unbounded(const double* G, const double* h, int n, double* theta) {
  if (n > max_) return false;
  for (int j = 0; j < n; ++j) passive_[static_cast<std::size_t>(j)] = 1;
  return solve_subset(G, h, n, n, theta);
}

bool BoundedLeastSquares::solve(const double* G, const double* h, const char* nonneg, int n, double* theta, int ld) {
  if (n > max_) return false;
  if (ld == 0) ld = n;
  if (ld < n) return false;
  double* z = z_.data();
  double* w = w_.data();
  // Start: unconstrained variables free, constrained ones at zero.
  for (int j = 0; j < n; ++j) passive_[static_cast<std::size_t>(j)] = nonneg[j] ? 0 : 1;
  if (!solve_subset(G, h, n, ld, theta)) return false;

  const int max_outer = 3 * n + 10;
  for (int outer = 0; outer < max_outer; ++outer) {
    // Gradient of the objective's negative: w = h - G theta.
    int best = -1;
    double best_w = 1e-12;
    for (int j = 0; j < n; ++j) {
      double s = h[j];
      for (int k = 0; k < n; ++k) s -= G[j * ld + k] * theta[k];
      w[j] = s;
      if (nonneg[j] && !passive_[static_cast<std::size_t>(j)] && s > best_w) {
        best_w = s;
        best = j;
      }
    }
    if (best < 0) return true;  // KKT conditions hold
    passive_[static_cast<std::size_t>(best)] = 1;
    for (int inner = 0; inner < n + 2; ++inner) {
      if (!solve_subset(G, h, n, ld, z)) return false;
      bool feasible = true;
      for (int j = 0; j < n; ++j) {
        if (nonneg[j] && passive_[static_cast<std::size_t>(j)] && z[j] <= 0.0) feasible = false;
      }
      if (feasible) {
        for (int j = 0; j < n; ++j) theta[j] = z[j];
        break;
      }
      double alpha = 1.0;
      for (int j = 0; j < n; ++j) {
        if (nonneg[j] && passive_[static_cast<std::size_t>(j)] && z[j] <= 0.0) {
          const double a = theta[j] / (theta[j] - z[j]);
          if (a < alpha) alpha = a;
        }
      }
      for (int j = 0; j < n; ++j) {
        theta[j] += alpha * (z[j] - theta[j]);
        if (nonneg[j] && passive_[static_cast<std::size_t>(j)] && theta[j] <= 1e-15) {
          theta[j] = 0.0;
          passive_[static_cast<std::size_t>(j)] = 0;
        }
      }
    }
  }
  return false;
}

}  // namespace bbw::calibration
