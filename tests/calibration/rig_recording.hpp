// Test helpers shared by the calibrator's accuracy tests.
#pragma once

#include <cmath>
#include <cstdlib>
#include <string>

#include "bbw/calibration/offline.hpp"
#include "bbw/calibration/rig_recording.hpp"
#include "bbw/plant/clamp_curve.hpp"
#include "bbw/scenario/load.hpp"

namespace bbw::calibration::test {

inline std::string source_path(const std::string& rel) {
  const char* root = std::getenv("BBW_SOURCE_DIR");
  return std::string(root ? root : BBW_SOURCE_DIR_FALLBACK) + "/" + rel;
}

// Least-squares cubic through the plant's true curve over [x0, x1] at a temperature.
inline Curve cubic_of_true_curve(const bbw::plant::ClampCurve& curve, double temperature_C, double x0, double x1) {
  double g[4][5] = {};
  for (int k = 0; k <= 200; ++k) {
    const double x = x0 + (x1 - x0) * k / 200.0;
    const double f = curve.force_kN(x, temperature_C, 0.0);
    const double p[4] = {1.0, x, x * x, x * x * x};
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) g[r][c] += p[r] * p[c];
      g[r][4] += p[r] * f;
    }
  }
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (r == c) continue;
      const double f = g[r][c] / g[c][c];
      for (int k = 0; k < 5; ++k) g[r][k] -= f * g[c][k];
    }
  }
  return Curve{g[3][4] / g[3][3], g[2][4] / g[2][2], g[1][4] / g[1][1], g[0][4] / g[0][0]};
}

}  // namespace bbw::calibration::test
