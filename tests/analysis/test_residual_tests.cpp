#include "bbw/analysis/residual_tests.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace bbw::analysis;

TEST(ResidualTests, WhiteNoiseIsWhiteAndItsLevelIsFound) {
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 0.5);
  std::vector<double> r(20000);
  for (auto& v : r) v = n(rng);
  const auto w = whiteness(r, 20);
  EXPECT_FALSE(w.significant) << "Q = " << w.ljung_box_q << " critical " << w.critical_q;
  EXPECT_NEAR(w.noise_rms, 0.5, 0.03);
  EXPECT_LT(w.structured_rms, 0.2);
}

TEST(ResidualTests, SlowStructureIsNotWhite) {
  std::mt19937 rng(12);
  std::normal_distribution<double> n(0.0, 0.1);
  std::vector<double> r(20000);
  for (std::size_t k = 0; k < r.size(); ++k) r[k] = std::sin(0.01 * k) + n(rng);
  const auto w = whiteness(r, 20);
  EXPECT_TRUE(w.significant);
  EXPECT_NEAR(w.noise_rms, 0.1, 0.01);
  EXPECT_GT(w.structured_rms / w.noise_rms, 5.0);
}

TEST(ResidualTests, DependenceFindsAFunctionOfAVariable) {
  std::mt19937 rng(13);
  std::normal_distribution<double> n(0.0, 0.3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> by(10000), r(10000), indep(10000);
  for (std::size_t k = 0; k < by.size(); ++k) {
    by[k] = u(rng);
    indep[k] = u(rng);
    r[k] = by[k] * by[k] + n(rng);
  }
  const auto d = dependence(r, by, 20, "by");
  EXPECT_TRUE(d.significant);
  EXPECT_GT(d.eta2, 0.3);
  const auto none = dependence(r, indep, 20, "indep");
  EXPECT_LT(none.eta2, 0.01);
  EXPECT_NEAR(chi2_upper_1pct(20), 37.57, 0.1);
}
