// Records one corner of a scenario with the plant (no DDS): the same CornerSim the corner
// process runs. Test helper shared by the calibrator's accuracy tests.
#pragma once

#include <cmath>
#include <cstdlib>
#include <string>

#include "bbw/calibration/offline.hpp"
#include "bbw/plant/clamp_curve.hpp"
#include "bbw/scenario/corner_sim.hpp"
#include "bbw/scenario/load.hpp"

namespace bbw::calibration::test {

inline std::string source_path(const std::string& rel) {
  const char* root = std::getenv("BBW_SOURCE_DIR");
  return std::string(root ? root : BBW_SOURCE_DIR_FALLBACK) + "/" + rel;
}

inline Recording record_corner(const bbw::scenario::Scenario& sc, std::size_t index) {
  bbw::scenario::CornerSim sim(sc, index);
  Recording rec;
  const auto steps = static_cast<std::size_t>(std::llround(sc.duration_s / sc.plant_dt_s));
  rec.time_s.reserve(steps);
  rec.position_rev.reserve(steps);
  rec.force_kN.reserve(steps);
  rec.truth_kN.reserve(steps);
  for (std::size_t k = 0; k < steps; ++k) {
    const auto& s = sim.step(sc.plant_dt_s);
    rec.time_s.push_back(s.time_s);
    rec.position_rev.push_back(s.position_rev);
    rec.force_kN.push_back(s.force_internal_kN);
    rec.truth_kN.push_back(s.force_external_kN);
    rec.speed_rev_s.push_back(s.speed_rev_s);
  }
  return rec;
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
