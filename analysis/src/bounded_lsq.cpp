#include "bbw/analysis/bounded_lsq.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bbw::analysis {

LsqProblem normal_equations(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                            const std::vector<Eigen::Index>& rows) {
  LsqProblem p;
  if (rows.empty()) {
    p.gram = x.transpose() * x;
    p.xty = x.transpose() * y;
    p.yty = y.squaredNorm();
    p.rows = static_cast<std::size_t>(x.rows());
    return p;
  }
  Eigen::MatrixXd xs(static_cast<Eigen::Index>(rows.size()), x.cols());
  Eigen::VectorXd ys(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    xs.row(static_cast<Eigen::Index>(r)) = x.row(rows[r]);
    ys(static_cast<Eigen::Index>(r)) = y(rows[r]);
  }
  p.gram = xs.transpose() * xs;
  p.xty = xs.transpose() * ys;
  p.yty = ys.squaredNorm();
  p.rows = rows.size();
  return p;
}

namespace {

// Unconstrained solve on the passive set P (indices into the scaled problem).
Eigen::VectorXd solve_on(const Eigen::MatrixXd& g, const Eigen::VectorXd& c, const std::vector<bool>& passive) {
  const Eigen::Index n = g.rows();
  std::vector<Eigen::Index> idx;
  for (Eigen::Index j = 0; j < n; ++j)
    if (passive[static_cast<std::size_t>(j)]) idx.push_back(j);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
  if (idx.empty()) return z;
  const auto m = static_cast<Eigen::Index>(idx.size());
  Eigen::MatrixXd gp(m, m);
  Eigen::VectorXd cp(m);
  for (Eigen::Index a = 0; a < m; ++a) {
    cp(a) = c(idx[static_cast<std::size_t>(a)]);
    for (Eigen::Index b = 0; b < m; ++b) gp(a, b) = g(idx[static_cast<std::size_t>(a)], idx[static_cast<std::size_t>(b)]);
  }
  const Eigen::VectorXd zp = gp.ldlt().solve(cp);
  for (Eigen::Index a = 0; a < m; ++a) z(idx[static_cast<std::size_t>(a)]) = zp(a);
  return z;
}

}  // namespace

Eigen::VectorXd solve_bounded(const LsqProblem& p, const std::vector<bool>& nonneg, double ridge) {
  const Eigen::Index n = p.gram.rows();
  if (static_cast<Eigen::Index>(nonneg.size()) != n) throw std::invalid_argument("solve_bounded: nonneg size");
  Eigen::VectorXd scale(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double d = p.gram(j, j);
    scale(j) = d > 0.0 ? 1.0 / std::sqrt(d) : 1.0;
  }
  Eigen::MatrixXd g = scale.asDiagonal() * p.gram * scale.asDiagonal();
  g.diagonal().array() += ridge;
  const Eigen::VectorXd c = scale.asDiagonal() * p.xty;

  std::vector<bool> passive(static_cast<std::size_t>(n));
  for (Eigen::Index j = 0; j < n; ++j) passive[static_cast<std::size_t>(j)] = !nonneg[static_cast<std::size_t>(j)];
  Eigen::VectorXd b = solve_on(g, c, passive);  // constrained ones are zero here

  const double tol = 1e-12 * (1.0 + c.cwiseAbs().maxCoeff());
  for (int outer = 0; outer < 10 * static_cast<int>(n) + 10; ++outer) {
    const Eigen::VectorXd w = c - g * b;
    Eigen::Index best = -1;
    double best_w = tol;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (nonneg[static_cast<std::size_t>(j)] && !passive[static_cast<std::size_t>(j)] && w(j) > best_w) {
        best_w = w(j);
        best = j;
      }
    }
    if (best < 0) break;
    passive[static_cast<std::size_t>(best)] = true;
    for (int inner = 0; inner < 10 * static_cast<int>(n) + 10; ++inner) {
      const Eigen::VectorXd z = solve_on(g, c, passive);
      double alpha = 1.0;
      bool infeasible = false;
      for (Eigen::Index j = 0; j < n; ++j) {
        if (nonneg[static_cast<std::size_t>(j)] && passive[static_cast<std::size_t>(j)] && z(j) <= 0.0) {
          infeasible = true;
          const double den = b(j) - z(j);
          if (den > 0.0) alpha = std::min(alpha, b(j) / den);
        }
      }
      if (!infeasible) {
        b = z;
        break;
      }
      b += alpha * (z - b);
      for (Eigen::Index j = 0; j < n; ++j) {
        if (nonneg[static_cast<std::size_t>(j)] && passive[static_cast<std::size_t>(j)] && b(j) <= 1e-15) {
          passive[static_cast<std::size_t>(j)] = false;
          b(j) = 0.0;
        }
      }
    }
  }
  return scale.asDiagonal() * b;
}

}  // namespace bbw::analysis
