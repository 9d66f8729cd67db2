#include "bbw/scenario/population.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace bbw::scenario {

plant::Caliper population_member(const PopulationSpec& spec, int index) {
  if (index < 0 || index >= spec.count) {
    throw std::out_of_range("population '" + spec.name + "': member " + std::to_string(index) + " not in [0, " +
                            std::to_string(spec.count) + ")");
  }
  return plant::draw_caliper(spec.base, spec.ranges, spec.seed, index);
}

std::string temperature_corner_name(double temperature_C) {
  char buf[32];
  if (std::fabs(temperature_C - std::round(temperature_C)) < 1e-9) {
    std::snprintf(buf, sizeof buf, "T%.0f", temperature_C);
  } else {
    std::snprintf(buf, sizeof buf, "T%.1f", temperature_C);
  }
  return buf;
}

Scenario population_scenario(const PopulationSpec& spec, int index) {
  const plant::Caliper c = population_member(spec, index);
  Scenario s;
  s.name = spec.name + "_c" + std::to_string(index);
  s.file = spec.file;
  s.seed = c.seed;
  s.duration_s = spec.duration_s;
  s.plant_dt_s = spec.plant_dt_s;
  s.plant_file = spec.plant_file;
  s.plant = c.params;
  for (double t : spec.temperatures_C) {
    CornerSpec k;
    k.name = temperature_corner_name(t);
    k.conditions.temperature_C = t;
    k.sensors = c.params.sensors;
    k.drive = spec.drive;
    s.corners.push_back(k);
  }
  return s;
}

}  // namespace bbw::scenario
