// Strict YAML loaders for the plant parameters (target bbw_plant_config). The schema is the
// file config/plant/ecaliper.yaml; every key is documented in docs/plant.md.
#pragma once

#include <string>

#include "bbw/common/strict_yaml.hpp"
#include "bbw/plant/params.hpp"

namespace bbw::plant {

// Loads a plant parameter file. Every section and key is required (the file is the record of
// the caliper), except motor.inductance_H and substeps. Throws config::ConfigError.
PlantParams load_plant_params(const std::string& file);
// Reads plant parameters from a mapping and finishes it.
PlantParams read_plant_params(config::Reader& r);

// Reads an `effects:` mapping: each of viscous_friction, load_dependent_friction,
// sensor_delay, thermal_drift, backlash, creep is optional; a present one is enabled unless it
// says `enabled: false`, and its parameters default to those of EffectsParams. Finishes `r`.
EffectsParams read_effects(config::Reader& r);

// Reads a partial `sensor:` mapping over `base` (only the keys present change). Finishes `r`.
SensorParams read_sensor_overrides(config::Reader& r, const SensorParams& base);

}  // namespace bbw::plant
