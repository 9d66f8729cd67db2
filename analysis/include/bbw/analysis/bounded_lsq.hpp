// Least squares with a sign constraint on some coefficients (Lawson-Hanson active set), solved on
// the normal equations of column-scaled data so that one Gram matrix serves many fits.
#pragma once

#include <Eigen/Dense>
#include <vector>

namespace bbw::analysis {

struct LsqProblem {
  Eigen::MatrixXd gram;   // X^T X
  Eigen::VectorXd xty;    // X^T y
  double yty = 0.0;       // y^T y
  std::size_t rows = 0;
};

// Forms the normal equations over the rows listed (all rows when `rows` is empty).
LsqProblem normal_equations(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                            const std::vector<Eigen::Index>& rows);

// Minimises |y - X b|^2 + ridge * trace-scaled |b|^2 subject to b_j >= 0 for nonneg[j].
// Columns are scaled to unit diagonal internally; returns b in the original column units.
Eigen::VectorXd solve_bounded(const LsqProblem& p, const std::vector<bool>& nonneg, double ridge = 1e-10);

}  // namespace bbw::analysis
