// Topic names and the QoS profile names each role uses, in one place.
#pragma once

namespace bbw::dds {

inline constexpr const char* kMeasurementTopic = "bbw/MeasurementBlock";
inline constexpr const char* kCommandTopic = "bbw/ClampCommand";
inline constexpr const char* kCalibrationTopic = "bbw/CalibrationState";
inline constexpr const char* kHealthTopic = "bbw/CornerHealth";
// A vehicle run (issue 15, idl/bbw_vehicle_msgs.idl): both in the run's partition, with the
// measurement profiles (one sample per CCU period, the barrier's "period done").
inline constexpr const char* kVehicleSensorsTopic = "bbw/VehicleSensors";
inline constexpr const char* kPedalTopic = "bbw/PedalSample";

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

}  // namespace bbw::dds
