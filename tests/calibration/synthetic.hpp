// A recording generated from exactly the calibrator's own model (a cubic curve plus a
// Maxwell-slip friction with the calibrator's thresholds). Used only to prove the fit
// recovers known parameters; accuracy claims use the plant, whose friction is richer.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "bbw/calibration/config.hpp"
#include "bbw/model/maxwell_slip.hpp"
#include "bbw/calibration/offline.hpp"

namespace bbw::calibration::test {

struct SyntheticTruth {
  Curve curve{0.05, 0.4, 2.0, 0.5};
  std::vector<double> delta_rev;
  std::vector<double> k_kN_per_rev;
};

// Increasing-amplitude cosine sweeps from x_low, 1 kHz, like paper Fig. 13.
inline Recording synthetic_recording(const SyntheticTruth& truth, double noise_kN, unsigned seed,
                                     double duration_s = 24.0) {
  Recording rec;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_kN);
  const std::size_t m = truth.delta_rev.size();
  std::vector<double> pos(m, 0.0);
  for (std::size_t i = 0; i < m; ++i) pos[i] = 0.5 + truth.delta_rev[i];
  const double dt = 0.001, period = 2.0, x_low = 0.5;
  const double amps[] = {1.0, 2.0, 3.0, 4.0, 5.0, 5.5};
  for (double t = 0.0; t < duration_s; t += dt) {
    const int cycle = static_cast<int>(t / period);
    const double a = amps[std::min<int>(cycle / 2, 5)];
    const double x = x_low + 0.5 * a * (1.0 - std::cos(2.0 * M_PI * t / period));
    const double fric = elements_step(x, truth.delta_rev.data(), pos.data(), m, truth.k_kN_per_rev.data(), nullptr);
    const double f_true = truth.curve.force_kN(x);
    rec.time_s.push_back(t);
    rec.position_rev.push_back(x);
    rec.force_kN.push_back(f_true + fric + (noise_kN > 0 ? noise(rng) : 0.0));
    rec.truth_kN.push_back(f_true);
  }
  return rec;
}

}  // namespace bbw::calibration::test
