// Strict YAML for the vehicle (config/vehicle/sedan.yaml): every key required, unknown keys and
// out-of-range values refused with the file, line, key path and rule (bbw::config::ConfigError).
#pragma once

#include <string>

#include "bbw/common/strict_yaml.hpp"
#include "bbw/vehicle/params.hpp"
#include "bbw/vehicle/pedal.hpp"
#include "bbw/vehicle/sensors.hpp"

namespace bbw::vehicle {

struct VehicleConfig {
  VehicleParams vehicle;
  WheelSpeedSensorParams wheel_speed;
  ImuParams imu;
  PedalParams pedal;
};

VehicleConfig read_vehicle_config(config::Reader& r);
VehicleConfig load_vehicle_config(const std::string& file);  // throws config::ConfigError

}  // namespace bbw::vehicle
