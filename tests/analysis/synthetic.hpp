// A small synthetic caliper recording for the analysis tests: a cubic-ish curve, a richer
// Maxwell-slip friction than the analysis fits (12 even elements), one or more injected effects
// and white noise. The truth is the clamp force without anything the sensor adds.
#pragma once

#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "bbw/analysis/analysis.hpp"
#include "bbw/analysis/effects.hpp"
#include "bbw/model/maxwell_slip.hpp"

namespace bbw::analysis::test {

struct SyntheticOptions {
  double duration_s = 8.0;
  double dt_s = 0.001;
  double noise_kN = 0.02;
  unsigned seed = 7;
  std::set<std::string> effects;  // viscous_friction, sensor_delay, backlash, creep,
                                  // load_dependent_friction, temperature_drift, coil
};

inline double curve_kN(double x_rev) { return ((0.1 * x_rev + 0.2) * x_rev + 1.0) * x_rev; }

inline Recording synthetic(const SyntheticOptions& o) {
  const auto n = static_cast<std::size_t>(o.duration_s / o.dt_s);
  const bool viscous = o.effects.count("viscous_friction"), delay = o.effects.count("sensor_delay"),
             backlash = o.effects.count("backlash"), creep = o.effects.count("creep"),
             load_dep = o.effects.count("load_dependent_friction"), temp = o.effects.count("temperature_drift"),
             coil = o.effects.count("coil");
  Recording r;
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0.0, o.noise_kN);
  const std::size_t m = 12;
  std::vector<double> delta(m), pos(m), k_delta(m, 0.11);
  calibration::thresholds(m, 0.12, false, 0.0, delta.data());
  PlayOperator play_op(0.12);
  FirstOrderLag lag(0.8);
  std::vector<double> coil_v(n);
  std::uniform_int_distribution<int> coin(0, 1);
  double coil_level = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    if (k % static_cast<std::size_t>(0.4 / o.dt_s) == 0) coil_level = 2.0 * coin(rng);
    coil_v[k] = coil_level;
  }
  std::vector<double> reading(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * o.dt_s;
    // Sinusoids of increasing amplitude (paper Fig. 13), with a small ripple for inner loops.
    const double amp = 1.0 + 4.5 * t / o.duration_s;
    const double x = 0.3 + 0.5 * amp * (1.0 - std::cos(2.0 * M_PI * 1.0 * t)) + 0.08 * std::sin(2.0 * M_PI * 7.0 * t);
    const double v = 0.5 * amp * 2.0 * M_PI * std::sin(2.0 * M_PI * t) + 0.08 * 2.0 * M_PI * 7.0 * std::cos(2.0 * M_PI * 7.0 * t);
    const double x_mech = backlash ? play_op.step(x) : x;
    double truth = curve_kN(x_mech);
    if (creep) truth -= 0.06 * lag.step(truth, o.dt_s);
    if (k == 0) std::fill(pos.begin(), pos.end(), x_mech);
    double friction = 0.0;
    for (std::size_t i = 0; i < m; ++i) friction += k_delta[i] * calibration::element_step(x_mech, delta[i], pos[i]);
    if (load_dep) friction *= 1.0 + 1.5 * truth / 35.0;
    double sensor = truth + friction;
    if (viscous) sensor += 0.06 * v;
    const double temperature = 40.0 + 20.0 * t / o.duration_s;
    if (temp) sensor += 0.06 * (temperature - 40.0);
    if (coil) sensor += 0.08 * coil_v[k] * v;
    r.time_s.push_back(t);
    r.position.push_back(x);
    r.truth.push_back(truth);
    r.temperature.push_back(temperature);
    reading[k] = sensor;
  }
  if (delay) reading = delayed(reading, o.dt_s, 0.006);
  for (std::size_t k = 0; k < n; ++k) r.force.push_back(reading[k] + noise(rng));
  if (coil) r.channels.push_back({"coil_V", coil_v});
  return r;
}

}  // namespace bbw::analysis::test
