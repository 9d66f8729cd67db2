#include "bbw/analysis/differentiate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace bbw::analysis;

TEST(Differentiate, ExactOnQuadraticsInsideTheSignal) {
  const double dt = 0.001;
  std::vector<double> x;
  for (int k = 0; k < 200; ++k) {
    const double t = k * dt;
    x.push_back(3.0 + 2.0 * t - 7.0 * t * t);
  }
  const auto v = sg_first_derivative(x, dt, 5);
  const auto a = sg_second_derivative(x, dt, 5);
  for (int k = 5; k < 195; ++k) {
    EXPECT_NEAR(v[k], 2.0 - 14.0 * k * dt, 1e-8);
    EXPECT_NEAR(a[k], -14.0, 1e-5);
  }
}

TEST(Differentiate, WiderWindowReducesNoise) {
  const double dt = 0.001;
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0.0, 1e-4);
  std::vector<double> x;
  for (int k = 0; k < 5000; ++k) x.push_back(std::sin(2.0 * M_PI * k * dt) + n(rng));
  auto err = [&](std::size_t h) {
    const auto v = sg_first_derivative(x, dt, h);
    double s = 0.0;
    for (int k = 100; k < 4900; ++k) {
      const double e = v[k] - 2.0 * M_PI * std::cos(2.0 * M_PI * k * dt);
      s += e * e;
    }
    return std::sqrt(s / 4800.0);
  };
  EXPECT_LT(err(10), 0.5 * err(1));
  EXPECT_EQ(half_width_for(0.01, 0.001), 5u);
  EXPECT_EQ(half_width_for(0.0001, 0.001), 1u);
}
