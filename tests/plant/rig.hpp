// Test helpers: a test-rig scenario built in code (plant defaults = config/plant/ecaliper.yaml)
// and a recording of CornerSim samples.
#pragma once

#include <cmath>
#include <vector>

#include "bbw/scenario/corner_sim.hpp"

namespace bbw::test {

inline scenario::PositionProfileSpec sweep_profile() {
  scenario::PositionProfileSpec p;
  p.start_rev = 0.0;
  p.ramp_s = 1.0;
  scenario::PaperSweep s;
  s.x_low_rev = 1.0;
  s.amplitudes_rev = {1.0, 2.0, 3.0, 4.0, 5.0};
  s.period_s = 2.0;
  s.cycles_per_amplitude = 1;
  p.segments.push_back(s);
  return p;
}

inline scenario::Scenario rig(const scenario::PositionProfileSpec& profile, double temperature_C = 40.0,
                              const plant::EffectsParams& effects = {}, double duration_s = 12.0) {
  scenario::Scenario s;
  s.name = "test_rig";
  s.seed = 5;
  s.duration_s = duration_s;
  scenario::CornerSpec c;
  c.name = "T";
  c.conditions.temperature_C = temperature_C;
  c.effects = effects;
  c.sensors = s.plant.sensors;
  c.drive.mode = scenario::DriveMode::Position;
  c.drive.position = profile;
  s.corners.push_back(c);
  return s;
}

inline std::vector<scenario::CornerSample> record(const scenario::Scenario& s, std::size_t corner = 0) {
  scenario::CornerSim sim(s, corner);
  const auto n = static_cast<std::size_t>(std::llround(s.duration_s / s.plant_dt_s));
  std::vector<scenario::CornerSample> out;
  out.reserve(n);
  for (std::size_t k = 0; k < n; ++k) out.push_back(sim.step(s.plant_dt_s));
  return out;
}

// Travel of the true spindle position since its last reversal, per sample, and direction
// (+1 rising, -1 falling) from the position profile's motion.
struct Travel {
  std::vector<double> since_reversal_rev;
  std::vector<int> direction;
};
inline Travel travel(const std::vector<scenario::CornerSample>& rec) {
  Travel t;
  t.since_reversal_rev.resize(rec.size(), 0.0);
  t.direction.resize(rec.size(), 0);
  int dir = 0;
  double turn = rec.empty() ? 0.0 : rec[0].position_true_rev;
  double extreme = turn;
  for (std::size_t i = 0; i < rec.size(); ++i) {
    const double x = rec[i].position_true_rev;
    // A reversal once the position moved 2e-3 rev back from its extreme.
    if (dir == 0) {
      if (x > turn + 2e-3) { dir = 1; extreme = x; }
      else if (x < turn - 2e-3) { dir = -1; extreme = x; }
    } else if (dir > 0) {
      if (x > extreme) extreme = x;
      else if (x < extreme - 2e-3) { dir = -1; turn = extreme; extreme = x; }
    } else {
      if (x < extreme) extreme = x;
      else if (x > extreme + 2e-3) { dir = 1; turn = extreme; extreme = x; }
    }
    t.direction[i] = dir;
    t.since_reversal_rev[i] = std::abs(x - turn);
  }
  return t;
}

}  // namespace bbw::test
