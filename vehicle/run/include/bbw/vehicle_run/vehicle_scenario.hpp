// A vehicle scenario (config/scenarios/vehicle/*.yaml, docs/vehicle.md): the four-corner scenario
// it runs the calipers of (with its fault schedule), the vehicle and brake-control files, the
// start speed, the road, the pedal's travel profile, the driver and the disc temperatures, and the
// processes it declares. Strict: unknown keys, missing keys and bad values name file, line, key.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "bbw/brake/params.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/vehicle/driver.hpp"
#include "bbw/vehicle/params_yaml.hpp"

namespace bbw::vehicle_run {

struct VehicleScenario {
  std::string name;
  std::string file;
  std::uint64_t seed = 1;
  faults::FaultScenario corners;        // the calipers (demand-driven), their plant and faults
  vehicle::VehicleConfig vehicle;
  vehicle::RoadParams road;
  brake::BrakeControlParams brake;
  double initial_speed_m_s = 0.0;
  std::vector<std::pair<double, double>> pedal;  // [t_s, travel fraction]
  bool driver = false;                  // a driver steers (else the wheel is held straight)
  vehicle::DriverParams driver_params;
  std::array<double, 4> disc_C{};
  std::array<double, 4> caliper_C{};    // from the corners' temperature_C
  std::vector<std::string> processes;   // declared process list: ccu, FL, FR, RL, RR, vehicle, pedal
  // Optional calibration phase: until cruise_until_s the engine holds the start speed (a drive
  // torque on the rear wheels, gain_Nm_per_m_s per wheel on the speed error) while the driver
  // modulates the brake, so the CCU's calibrator sees hysteresis cycles before the stop. The stop
  // (its onset, distance, ideal) begins at the first pedal travel after it. 0: none.
  double cruise_until_s = 0.0;
  double cruise_gain_Nm_per_m_s = 3000.0;
};

VehicleScenario load_vehicle_scenario(const std::string& file);  // throws config::ConfigError
// A file is a vehicle scenario when it has a top-level `vehicle:` key.
bool is_vehicle_scenario(const std::string& file);

}  // namespace bbw::vehicle_run
