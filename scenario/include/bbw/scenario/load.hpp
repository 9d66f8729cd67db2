// Strict YAML loader for scenario files (config/scenarios/*.yaml). Any unknown key, missing
// required key, wrong type or out-of-range value throws config::ConfigError naming the file,
// line, key path and rule. Schema: docs/plant.md, "Scenario files".
#pragma once

#include <functional>
#include <string>

#include "bbw/common/strict_yaml.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::scenario {

// Lets another component read extra top-level keys (e.g. `faults:`) from the same file: it is
// called with the top-level mapping after the standard keys are read and before unknown keys
// are rejected; keys it reads count as known.
using ExtraKeys = std::function<void(config::Reader& top)>;

Scenario load_scenario(const std::string& file, const ExtraKeys& extra = {});
// The same from text (tests); `name` stands in for the file and relative plant paths resolve
// against its directory.
Scenario load_scenario_string(const std::string& text, const std::string& name, const ExtraKeys& extra = {});

}  // namespace bbw::scenario
