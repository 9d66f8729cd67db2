// Topic names and the QoS profile names each role uses, in one place.
#pragma once

#include <cstdint>

namespace bbw::dds {

inline constexpr const char* kMeasurementTopic = "bbw/MeasurementBlock";
inline constexpr const char* kCommandTopic = "bbw/ClampCommand";
inline constexpr const char* kCalibrationTopic = "bbw/CalibrationState";
inline constexpr const char* kHealthTopic = "bbw/CornerHealth";
// A vehicle run (issue 15, idl/bbw_vehicle_msgs.idl): both in the run's partition, with the
// measurement profiles (one sample per CCU period, the barrier's "period done").
inline constexpr const char* kVehicleSensorsTopic = "bbw/VehicleSensors";
inline constexpr const char* kPedalTopic = "bbw/PedalSample";
// The vehicle's caliper temperatures to the corners, every N periods (idl/bbw_vehicle_msgs.idl).
inline constexpr const char* kCaliperTemperatureTopic = "bbw/CaliperTemperatures";

struct ProfileNames {
  const char* measurement_writer;
  const char* measurement_reader;
  const char* command_writer;
  const char* command_reader;
  const char* state_writer = "state_writer";
  const char* state_reader = "state_reader";
};

// Lockstep: no wall-clock QoS. Realtime: deadline and liveliness on measurements and commands.
constexpr ProfileNames profiles_for(bool lockstep) {
  if (lockstep) {
    return {"measurement_writer_lockstep", "measurement_reader_lockstep", "command_writer_lockstep",
            "command_reader_lockstep"};
  }
  return {"measurement_writer_realtime", "measurement_reader_realtime", "command_writer_realtime",
          "command_reader_realtime"};
}

// With a hot-standby CCU (issue 16): the same, with the commands under EXCLUSIVE ownership and a
// 10 ms deadline, and in lockstep measurement histories of 1024 blocks (the CCU that does not own
// the corners' commands may lag them; config/dds/bbw_profiles.xml).
constexpr ProfileNames profiles_for(bool lockstep, bool standby) {
  ProfileNames p = profiles_for(lockstep);
  if (standby && lockstep) {
    p.measurement_writer = "measurement_writer_lockstep_standby";
    p.measurement_reader = "measurement_reader_lockstep_standby";
  }
  if (standby) {
    p.command_writer = lockstep ? "command_writer_lockstep_owned" : "command_writer_realtime_owned";
    p.command_reader = lockstep ? "command_reader_lockstep_owned" : "command_reader_realtime_owned";
  }
  return p;
}

// Ownership strength of a CCU's command writers (issue 16, docs/faults.md "Hand-back"): the CCU
// with fewer outages leads, the primary at equal counts. An outage: the CCU was stopped and
// continued, or cut off from every corner; either may have moved the corners to the other CCU,
// and its state is stale when it returns. Strength only falls, so a returning CCU never takes
// the corners back from one that stayed. (A stall beyond the command deadline is no outage: the
// corners go to the other CCU for the stall and come back, with the same commands.)
inline constexpr std::uint32_t kStrengthBase = 1000000000;
inline constexpr std::uint32_t kStrengthPerOutage = 1000;
constexpr std::uint32_t ccu_strength(bool primary, std::uint32_t outages) {
  const std::uint32_t n = outages < 999999 ? outages : 999999;
  return kStrengthBase - n * kStrengthPerOutage + (primary ? 1u : 0u);
}

}  // namespace bbw::dds
