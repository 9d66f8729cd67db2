#include "bbw/faults/outcome.hpp"

namespace bbw::faults {

const char* reaction_to(Finding f) {
  switch (f) {
    case Finding::LoadCellOffset:
    case Finding::LoadCellStuck:
    case Finding::LoadCellNoisy:
    case Finding::LoadCellMissing: return "curve-based estimate and curve feedback from the last good curve";
    case Finding::ResolverOffset:
    case Finding::ResolverStuck: return "load-cell estimate with friction frozen; calibrator stopped";
    case Finding::ActuatorTorqueLoss: return "kept in service (the loop absorbs the loss)";
    case Finding::ActuatorLost:
    case Finding::ActuatorTracking:
    case Finding::LinkLost:
    case Finding::ProcessLost: return "share redistributed to the remaining corners";
    case Finding::ActuatorNotReleasing:
      return "commanded to release; its held force counted on its axle, the rest redistributed";
    case Finding::None: return "none";
  }
  return "none";
}

FaultOutcome assess(const FaultSpec& fault, const FaultMonitor& monitor) {
  FaultOutcome o;
  o.fault = fault;
  if (monitor.corner() != fault.target) return o;
  // The injected part first, then any other part: a wrong isolation is still a detection.
  const Part expected = fault.type == FaultType::Kill ? Part::Process : fault.part;
  const Part order[] = {expected, Part::Network, Part::Process, Part::LoadCell, Part::Resolver, Part::Actuator};
  for (Part p : order) {
    const Diagnosis& d = monitor.diagnosis(p);
    if (!d.present || d.detected_s < fault.at_s) continue;
    o.detected = true;
    o.detected_s = d.detected_s;
    o.latency_ms = 1e3 * (d.detected_s - fault.at_s);
    o.diagnosis = d.finding;
    o.correct = part_of(d.finding) == expected;
    o.reaction = reaction_to(d.finding);
    break;
  }
  return o;
}

}  // namespace bbw::faults
