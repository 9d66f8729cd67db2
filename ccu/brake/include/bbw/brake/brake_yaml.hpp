// Strict YAML for the CCU's brake functions (config/vehicle/brake_control.yaml): every key
// required; errors name the file, line, key path and rule.
#pragma once

#include <string>

#include "bbw/brake/params.hpp"
#include "bbw/common/strict_yaml.hpp"

namespace bbw::brake {

BrakeControlParams read_brake_control(config::Reader& r);
BrakeControlParams load_brake_control(const std::string& file);

}  // namespace bbw::brake
