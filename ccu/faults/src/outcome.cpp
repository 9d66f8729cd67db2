#include "bbw/faults/outcome.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

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

Finding finding_from_name(const std::string& name) {
  constexpr Finding kAll[] = {Finding::LoadCellOffset,     Finding::LoadCellStuck,  Finding::LoadCellNoisy,
                              Finding::LoadCellMissing,    Finding::ResolverOffset, Finding::ResolverStuck,
                              Finding::ActuatorTorqueLoss, Finding::ActuatorLost,   Finding::ActuatorTracking,
                              Finding::ActuatorNotReleasing, Finding::LinkLost,     Finding::ProcessLost};
  for (Finding f : kAll) {
    if (name == to_string(f)) return f;
  }
  return Finding::None;
}

FaultOutcome score_fault(const FaultSpec& f, const std::vector<DetectionEvent>& detections) {
  FaultOutcome r;
  r.fault = f;
  const Part expected = f.type == FaultType::Kill ? Part::Process : f.part;
  const DetectionEvent* best = nullptr;
  const DetectionEvent* first = nullptr;
  for (const DetectionEvent& d : detections) {
    if (d.corner != f.target || d.finding == Finding::None || d.detected_s < f.at_s - 1e-9) continue;
    if (first == nullptr || d.detected_s < first->detected_s) first = &d;
    const bool right = part_of(d.finding) == expected;
    if (best == nullptr) {
      best = &d;
    } else {
      const bool best_right = part_of(best->finding) == expected;
      if ((right && !best_right) || (right == best_right && d.detected_s < best->detected_s)) best = &d;
    }
  }
  if (best == nullptr) return r;
  r.detected = true;
  r.detected_s = first->detected_s;
  r.latency_ms = 1e3 * (first->detected_s - f.at_s);
  r.diagnosis_s = best->detected_s;
  r.diagnosis_latency_ms = 1e3 * (best->detected_s - f.at_s);
  // The diagnosis is that part's final finding: a later upgrade of the same part (e.g.
  // actuator_lost -> actuator_not_releasing once a release is commanded) refines it.
  const DetectionEvent* last = best;
  for (const DetectionEvent& d : detections) {
    if (d.corner == f.target && part_of(d.finding) == part_of(best->finding) && d.detected_s >= last->detected_s) last = &d;
  }
  r.diagnosis = last->finding;
  r.correct = part_of(best->finding) == expected;
  r.reaction = reaction_to(last->finding);
  return r;
}

FaultOutcome score_ccu_kill(const FaultSpec& f, const std::vector<double>& ccu_lost_s) {
  FaultOutcome r;
  r.fault = f;
  // The corners' watchdogs detect a lost CCU; the diagnosis is right when every corner did.
  double first = std::numeric_limits<double>::infinity();
  bool all = !ccu_lost_s.empty();
  for (const double t : ccu_lost_s) {
    if (t >= f.at_s - 1e-9) first = std::min(first, t);
    all = all && t >= f.at_s - 1e-9;
  }
  if (std::isfinite(first)) {
    r.detected = true;
    r.detected_s = r.diagnosis_s = first;
    r.latency_ms = r.diagnosis_latency_ms = 1e3 * (first - f.at_s);
    r.ccu_lost = true;
    r.correct = all;
    r.reaction = "corners hold the last command, then ramp to the default clamp force (never release)";
  }
  return r;
}

std::string diagnosis_name(const FaultOutcome& o) {
  if (o.ccu_lost) return "ccu_lost";
  if (o.diagnosis == Finding::None) return "none";
  return to_string(o.diagnosis);
}

}  // namespace bbw::faults
