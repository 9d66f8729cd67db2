// A population spec (config/population/*.yaml): which calipers to draw (seed, count, ranges
// around a base plant file), at which temperatures, with which rig drive. Loaded strictly;
// member i becomes a rig scenario with one corner per temperature (T28, T40, ...). A scenario
// file picks one member for its plant with `population: {spec: FILE, member: I}`.
// Schema: docs/plant.md ("Caliper population").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "bbw/plant/population.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::scenario {

struct PopulationSpec {
  std::string file;
  std::string name;
  std::uint64_t seed = 1;
  int count = 1;
  std::vector<double> temperatures_C;
  double duration_s = 34.0;
  double plant_dt_s = 0.001;
  std::string plant_file;          // the base caliper
  plant::PlantParams base;
  DriveSpec drive;                 // position mode (rig)
  plant::PopulationRanges ranges;
};

PopulationSpec load_population_spec(const std::string& file);
PopulationSpec load_population_spec_string(const std::string& text, const std::string& name);

// Member `index` (0 <= index < count) of the population.
plant::Caliper population_member(const PopulationSpec& spec, int index);
// Member `index` as a rig scenario: one corner per temperature named "T<temperature>",
// noise seeds from the member's seed.
Scenario population_scenario(const PopulationSpec& spec, int index);
// "T28", "T40.5".
std::string temperature_corner_name(double temperature_C);

}  // namespace bbw::scenario
