// What the CCU receives from a corner per sample, as the fault monitor sees it. The CCU
// process fills it from a DDS sample, the in-memory harness from a scenario::CornerSample.
#pragma once

#include <cstdint>
#include <limits>

namespace bbw::faults {

struct CornerReading {
  std::uint64_t seq = 0;               // per corner incarnation, 1 for its first sample
  double time_s = 0.0;
  double position_rev = 0.0;           // resolver
  double speed_rev_per_s = 0.0;        // resolver speed
  double load_cell_kN = 0.0;           // internal load cell (NaN: no value, a dropout)
  double motor_current_A = 0.0;
  double temperature_C = std::numeric_limits<double>::quiet_NaN();  // caliper temperature
  // The clamp-force command the corner was following in force mode; NaN in position mode.
  double force_command_kN = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace bbw::faults
