// Least squares with optional non-negativity on chosen parameters, in Gram form:
//   minimise 0.5 t' G t - h' t  subject to  t_j >= 0 for every j with nonneg[j].
// G = A'A (+ ridge) is symmetric positive definite on the free set. Lawson-Hanson active-set
// iterations; each sub-problem is solved by Cholesky. Workspace sized at construction:
// solve() does not allocate.
#pragma once

#include <vector>

namespace bbw::calibration {

class BoundedLeastSquares {
 public:
  explicit BoundedLeastSquares(int max_params);

  // G is n x n row-major, row j starting at G + j ld (ld = 0: n; a block of a larger matrix
  // otherwise). Returns false when a sub-problem is not positive definite or the iteration
  // limit is hit; theta is then left at the last feasible point.
  bool solve(const double* G, const double* h, const char* nonneg, int n, double* theta, int ld = 0);

  // Cholesky solve of the whole system without bounds (the paper's plain least squares).
  bool solve_unbounded(const double* G, const double* h, int n, double* theta);

  std::size_t bytes() const;

 private:
  bool solve_subset(const double* G, const double* h, int n, int ld, double* z);  // on passive_

  int max_;
  std::vector<double> l_;       // Cholesky factor workspace, lower triangle packed by rows
  std::vector<double> rhs_;
  std::vector<int> idx_;        // indices of passive (free) variables
  std::vector<char> passive_;
  std::vector<double> z_;
  std::vector<double> w_;
};

}  // namespace bbw::calibration
