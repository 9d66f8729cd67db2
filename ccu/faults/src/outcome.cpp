#include "bbw/faults/outcome.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace bbw::faults {

namespace {
// The load-cell bias the diagnosis promises to find (docs/faults.md, "Detectability limits"), and
// the window a bias at or above it is scored in.
constexpr double kBiasLimit_kN = 1.0;
constexpr double kBiasWindow_s = 0.5;
}  // namespace

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

double detection_window_s(const FaultSpec& f) {
  switch (f.type) {
    case FaultType::Bias: return kBiasWindow_s;
    case FaultType::Drift: {
      const double rate = std::abs(f.rate_kN_per_s);
      return (rate > 0.0 ? kBiasLimit_kN / rate : 0.0) + kBiasWindow_s;
    }
    case FaultType::Stuck: return 1.0;
    case FaultType::NoiseBurst: return 0.5;
    case FaultType::Dropout: return 0.1;
    case FaultType::Offset: return 0.5;
    case FaultType::TorqueLoss: return 1.0;
    case FaultType::TotalLoss: return 0.5;
    case FaultType::Seized: return 0.5;
    case FaultType::Silence:
    case FaultType::Delay:
    case FaultType::LinkCut:
    case FaultType::Hang:
    case FaultType::Kill: return 0.1;
  }
  return 0.0;
}

bool right_finding(const FaultSpec& f, Finding d) {
  switch (f.type) {
    case FaultType::Bias:
    case FaultType::Drift: return d == Finding::LoadCellOffset;
    case FaultType::Stuck: return d == (f.part == Part::Resolver ? Finding::ResolverStuck : Finding::LoadCellStuck);
    case FaultType::NoiseBurst: return d == Finding::LoadCellNoisy;
    case FaultType::Dropout: return d == Finding::LoadCellMissing;
    case FaultType::Offset: return d == Finding::ResolverOffset;
    // A loss of 75 % or more leaves the motor below the lost threshold (a quarter of its torque).
    case FaultType::TorqueLoss:
      return d == Finding::ActuatorTorqueLoss || (d == Finding::ActuatorLost && f.torque_loss_percent >= 75.0);
    // Without motor torque a brake whose screw the clamp load cannot back-drive holds its force:
    // not releasing is that loss seen from outside (the same reaction: out of use).
    case FaultType::TotalLoss:
      return d == Finding::ActuatorLost || d == Finding::ActuatorTracking || d == Finding::ActuatorNotReleasing;
    case FaultType::Seized:
      return d == Finding::ActuatorLost || d == Finding::ActuatorNotReleasing || d == Finding::ActuatorTracking;
    case FaultType::Silence:
    case FaultType::Delay:
    case FaultType::LinkCut: return d == Finding::LinkLost;
    // A dead (or hung) process and a dead link look the same until the participant's lease runs out.
    case FaultType::Hang:
    case FaultType::Kill: return d == Finding::ProcessLost || d == Finding::LinkLost;
  }
  return false;
}

namespace {

bool masks(const FaultSpec& by, const FaultSpec& f) {
  const bool itself = by.type == f.type && by.part == f.part && by.at_s == f.at_s;
  if (itself || by.target != f.target || is_ccu(by.target)) return false;
  if (by.type == FaultType::Silence) return true;
  const bool actuator = f.type == FaultType::TorqueLoss || f.type == FaultType::TotalLoss || f.type == FaultType::Seized;
  return actuator && by.part == Part::Resolver && by.type == FaultType::Stuck;
}

}  // namespace

double observable_from(const FaultSpec& f, const std::vector<FaultSpec>& faults) {
  double from_s = f.at_s;
  for (bool moved = true; moved && std::isfinite(from_s);) {
    moved = false;
    for (const FaultSpec& g : faults) {
      if (masks(g, f) && g.at_s <= from_s + 1e-9 && g.end_s() > from_s + 1e-9) {
        from_s = g.end_s();
        moved = true;
      }
    }
  }
  return from_s;
}

namespace {

// The participants' discovery lease (config/dds/bbw_profiles.xml, leaseDuration 2 s): a killed
// process is named (process_lost) by the lease running out, or earlier by its restarted
// incarnation's first samples, which may come well after the restart (its discovery).
constexpr double kParticipantLease_s = 2.0;

bool explains(const FaultSpec& f, const DetectionEvent& d) {
  if (f.target != d.corner || !right_finding(f, d.finding) || d.detected_s < f.at_s - 1e-9) return false;
  double end_s = f.type == FaultType::Kill && !f.restart_after_s ? std::numeric_limits<double>::infinity() : f.end_s();
  // A restarted process is named at the latest when the lease of the killed one runs out.
  if (f.type == FaultType::Kill && d.finding == Finding::ProcessLost) end_s = std::max(end_s, f.at_s + kParticipantLease_s);
  return d.detected_s <= end_s + detection_window_s(f) + 1e-9;
}

}  // namespace

RunScore score_run(const std::vector<FaultSpec>& faults, const std::vector<DetectionEvent>& detections,
                   double run_end_s) {
  RunScore score;
  for (const DetectionEvent& d : detections) {
    if (d.finding == Finding::None) continue;
    bool explained = false;
    for (const FaultSpec& f : faults) explained = explained || (!is_ccu(f.target) && explains(f, d));
    if (!explained) score.false_alarms.push_back(d);
  }
  for (const FaultSpec& f : faults) {
    if (is_ccu(f.target)) continue;
    FaultOutcome r;
    r.fault = f;
    r.observable_s = observable_from(f, faults);
    const double end_s = std::min(f.end_s(), run_end_s);
    if (!(r.observable_s < end_s - 1e-9)) {
      r.masked = true;
      r.observable_s = std::min(r.observable_s, end_s);
    }
    const double until_s = r.observable_s + detection_window_s(f) + 1e-9;
    const DetectionEvent* first_right = nullptr;
    const DetectionEvent* first_any = nullptr;
    for (const DetectionEvent& d : detections) {
      if (d.corner != f.target || d.finding == Finding::None || d.detected_s < f.at_s - 1e-9) continue;
      if (first_any == nullptr || d.detected_s < first_any->detected_s) first_any = &d;
      if (d.detected_s <= until_s && right_finding(f, d.finding) &&
          (first_right == nullptr || d.detected_s < first_right->detected_s)) {
        first_right = &d;
      }
    }
    if (first_right != nullptr) {
      // The diagnosis is the last right finding for the fault (actuator_lost -> not releasing
      // once a release is commanded; link_lost -> process_lost when the process is named), made
      // when its part was first rightly found.
      const DetectionEvent* last = first_right;
      for (const DetectionEvent& d : detections) {
        if (explains(f, d) && d.detected_s >= last->detected_s) last = &d;
      }
      const DetectionEvent* made = last;
      for (const DetectionEvent& d : detections) {
        if (explains(f, d) && part_of(d.finding) == part_of(last->finding) && d.detected_s < made->detected_s) made = &d;
      }
      r.diagnosis = last->finding;
      r.diagnosis_s = made->detected_s;
      r.diagnosis_latency_ms = 1e3 * (made->detected_s - f.at_s);
      r.reaction = reaction_to(last->finding);
    } else if (first_any != nullptr) {
      // Shown, not counted: what the corner raised instead (or too late).
      r.diagnosis = first_any->finding;
      r.diagnosis_s = first_any->detected_s;
      r.diagnosis_latency_ms = 1e3 * (first_any->detected_s - f.at_s);
      r.reaction = reaction_to(first_any->finding);
    }
    if (first_right != nullptr && !r.masked) {
      r.detected = true;
      r.detected_s = first_right->detected_s;
      r.latency_ms = 1e3 * std::max(0.0, first_right->detected_s - r.observable_s);
      bool clean = true;
      for (const DetectionEvent& d : score.false_alarms) {
        clean = clean && !(d.corner == f.target && d.detected_s >= f.at_s - 1e-9 && d.detected_s <= until_s);
      }
      r.correct = clean;
    }
    score.outcomes.push_back(r);
  }
  return score;
}

FaultOutcome score_fault(const FaultSpec& f, const std::vector<DetectionEvent>& detections) {
  RunScore s = score_run({f}, detections);
  if (s.outcomes.empty()) throw std::invalid_argument("score_fault: a CCU kill is scored by score_ccu_kill");
  return s.outcomes.front();
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
