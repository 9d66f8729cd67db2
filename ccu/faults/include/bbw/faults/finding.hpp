// What the fault monitor concludes: findings, the part each names, a part's diagnosis, and the
// link events the transport reports (docs/faults.md, "Detection").
#pragma once

#include <cstdint>

#include "bbw/faults/schedule.hpp"

namespace bbw::faults {

enum class Finding : std::uint8_t {
  None,
  LoadCellOffset,    // residual, no resolver signature (bias, drift)
  LoadCellStuck,
  LoadCellNoisy,
  LoadCellMissing,   // dropout
  ResolverOffset,
  ResolverStuck,
  ActuatorTorqueLoss,  // part of the torque is missing; the loop still reaches the command
  ActuatorLost,        // (almost) no torque for the current drawn
  ActuatorTracking,    // cannot follow a reachable command
  ActuatorNotReleasing,  // holds a force well above the command (jammed, seized): over-application
  LinkLost,          // deadline missed / no samples
  ProcessLost,       // liveliness lost, or a new process of the corner joined
};
const char* to_string(Finding f);
Part part_of(Finding f);  // Finding::None -> Part::LoadCell (unused)

struct Diagnosis {
  bool present = false;    // confirmed at least once
  bool active = false;     // still in force (sensor/actuator findings latch; link/process clear)
  Finding finding = Finding::None;
  double onset_s = 0.0;    // when the condition started (best estimate)
  double detected_s = 0.0; // when it was confirmed
  double finding_s = 0.0;  // when the current finding was confirmed (later after an upgrade)
};

// Restarted: a new process of the corner (a higher incarnation) has sent its first samples, so
// the one before it is gone: an outage still open is the process's death, not the link's.
// LivelinessLost: the corner's writer is gone (its participant's lease ran out or it left).
// LeaseLapsed: the writer's own liveliness lease (realtime: 30 ms) lapsed; that cannot tell a
// process stalled on a loaded machine, or a late link, from a dead one, so it is a lost link (as a
// missed deadline), and the process is named only when its writer is gone or it restarts.
enum class LinkEvent : std::uint8_t { DeadlineMissed, LivelinessLost, LivelinessRecovered, Restarted, LeaseLapsed };

}  // namespace bbw::faults
