// What the CCU receives from a corner per sample: the one shape of a sample on the CCU's side of
// the wire. It is the calibrator's Sample (time, resolver position and speed, load cell,
// temperature) plus what the fault monitor needs besides: the sample's sequence number, the
// motor current and the force command. The CCU process fills it from a DDS sample
// (node/src/ccu_node.cpp), the calibrator takes it as it is.
#pragma once

#include <cstdint>
#include <limits>

#include "bbw/calibration/calibrator.hpp"

namespace bbw::faults {

struct CornerReading : calibration::Sample {
  // force_kN: the internal load cell (NaN: no value, a dropout); speed_rev_per_s: the resolver
  // speed, always sent by a corner (0 until set, not the calibrator's "not given").
  CornerReading() { speed_rev_per_s = 0.0; }
  std::uint64_t seq = 0;               // per corner incarnation, 1 for its first sample
  double motor_current_A = 0.0;
  // The clamp-force command the corner was following in force mode; NaN in position mode.
  double force_command_kN = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace bbw::faults
