#include "bbw/calibration/rig_recording.hpp"

#include <cmath>

#include "bbw/scenario/corner_sim.hpp"

namespace bbw::calibration {

Recording record_corner(const bbw::scenario::Scenario& scenario, std::size_t corner_index) {
  bbw::scenario::CornerSim sim(scenario, corner_index);
  Recording rec;
  const auto steps = static_cast<std::size_t>(std::llround(scenario.duration_s / scenario.plant_dt_s));
  rec.time_s.reserve(steps);
  rec.position_rev.reserve(steps);
  rec.force_kN.reserve(steps);
  rec.truth_kN.reserve(steps);
  rec.speed_rev_per_s.reserve(steps);
  for (std::size_t k = 0; k < steps; ++k) {
    const auto& s = sim.step(scenario.plant_dt_s);
    rec.time_s.push_back(s.time_s);
    rec.position_rev.push_back(s.position_rev);
    rec.force_kN.push_back(s.force_internal_kN);
    rec.truth_kN.push_back(s.force_external_kN);
    rec.speed_rev_per_s.push_back(s.speed_rev_per_s);
  }
  return rec;
}

}  // namespace bbw::calibration
