#include "bbw/analysis/bounded_lsq.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace bbw::analysis;

TEST(BoundedLsq, UnconstrainedMatchesLeastSquares) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::MatrixXd x(500, 4);
  for (int i = 0; i < 500; ++i)
    for (int j = 0; j < 4; ++j) x(i, j) = n(rng) * (j + 1) * 100.0;
  const Eigen::Vector4d b(1.0, -2.0, 0.5, 3.0);
  const Eigen::VectorXd y = x * b;
  const auto est = solve_bounded(normal_equations(x, y, {}), {false, false, false, false});
  EXPECT_NEAR((est - b).norm(), 0.0, 1e-6);
}

TEST(BoundedLsq, NegativeTruthIsClampedAndOthersRefit) {
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::MatrixXd x(1000, 3);
  for (int i = 0; i < 1000; ++i)
    for (int j = 0; j < 3; ++j) x(i, j) = n(rng);
  const Eigen::Vector3d b(2.0, -1.0, 0.7);
  const Eigen::VectorXd y = x * b;
  const auto est = solve_bounded(normal_equations(x, y, {}), {false, true, true});
  EXPECT_DOUBLE_EQ(est(1), 0.0);
  EXPECT_NEAR(est(2), 0.7, 0.1);
  EXPECT_GE(est(2), 0.0);
  // With orthogonal-ish columns the free one stays close to its value.
  EXPECT_NEAR(est(0), 2.0, 0.15);
}

TEST(BoundedLsq, RowSubsetUsesOnlyThoseRows) {
  Eigen::MatrixXd x(4, 1);
  x << 1, 1, 1, 1;
  Eigen::VectorXd y(4);
  y << 1, 1, 5, 5;
  const auto est = solve_bounded(normal_equations(x, y, {2, 3}), {false});
  EXPECT_NEAR(est(0), 5.0, 1e-9);
}
