// The one fault scorer (docs/faults.md, "Reporting"): each injected fault against what was
// detected, used by bbw_launch (summary.json's `faults` list, from ccu.stats) and by the
// closed-loop tests (tests/faults, from CcuNode::detections()). Pure.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "bbw/faults/finding.hpp"
#include "bbw/faults/schedule.hpp"

namespace bbw::faults {

// One detection in the CCU's log: a diagnosis confirmed (again, or upgraded) on a corner.
struct DetectionEvent {
  Target corner = Target::FL;
  Finding finding = Finding::None;
  double onset_s = 0.0;
  double detected_s = 0.0;
};

struct FaultOutcome {
  FaultSpec fault;
  // Strict (issue 14): detected only by a right finding for the fault's type (right_finding) on
  // its corner within the type's stated window after the injection (detection_window_s).
  bool detected = false;
  double detected_s = 0.0;      // the first right finding in the window (CCU kill: the first watchdog)
  double latency_ms = 0.0;      // detected_s - observable_s
  // When the fault could first show itself (observable_from): its injection, or the end of what
  // masked it there. The window runs from here. masked: nothing could show it before it ended;
  // such a fault is neither detected nor missed (the campaign counts it apart).
  double observable_s = 0.0;
  bool masked = false;
  double diagnosis_s = 0.0;     // when the diagnosis below was made
  double diagnosis_latency_ms = 0.0;
  Finding diagnosis = Finding::None;  // the right finding's final form (an upgrade refines it); else the first finding
  bool ccu_lost = false;        // CCU kill: the diagnosis is the corners' "CCU lost"
  // detected, and nothing on the corner within the window that no injected fault explains
  // (CCU kill: every corner saw it).
  bool correct = false;
  const char* reaction = "none";
  double delivered_share = 1.0; // delivered / demanded total clamp force while it lasted (caller)
};

// The stated detection window of a fault (docs/faults.md, "Scoring"): a right finding later than
// at_s + this is a miss. Drift: the time the drift needs to reach the bias limit, plus the bias
// window.
double detection_window_s(const FaultSpec& fault);
// When `fault` could first show itself, given the run's other faults (`faults`, which may hold it):
// its injection, unless another fault on its corner masks it then, and then that fault's end,
// again as long as one masks it (+inf: masked until the end). Masking (docs/faults.md, "Masked
// faults"): a link silence masks any fault on its corner (the CCU hears nothing of it); a stuck
// resolver masks an actuator fault (torque loss, total loss, seized: the corner cannot commutate
// its motor and drives no current, corner_unit::ControllerParams::frozen_resolver_samples, so a
// drive without torque and a healthy one without current are the same drive).
double observable_from(const FaultSpec& fault, const std::vector<FaultSpec>& faults);
// Whether `finding` names `fault` rightly (its part and type; e.g. a bias or drift is a
// load_cell_offset, a seized actuator is actuator_lost or actuator_not_releasing).
bool right_finding(const FaultSpec& fault, Finding finding);

// A run's faults against every detection: per fault its outcome, and the detections that no
// injected fault explains (false alarms). A detection is explained by a fault on its corner when
// it is a right finding for it at or after the injection and before the fault's end plus its
// window (a late right finding is a miss, not a false alarm).
struct RunScore {
  std::vector<FaultOutcome> outcomes;         // in schedule order (CCU kills scored elsewhere: not here)
  std::vector<DetectionEvent> false_alarms;   // in detection order
};
// run_end_s: a fault hidden until then is masked too.
RunScore score_run(const std::vector<FaultSpec>& faults, const std::vector<DetectionEvent>& detections,
                   double run_end_s = std::numeric_limits<double>::infinity());

// One corner fault alone (score_run with that fault only).
FaultOutcome score_fault(const FaultSpec& fault, const std::vector<DetectionEvent>& detections);

// A CCU kill against the corners' watchdogs: `ccu_lost_s` per corner, when it found the CCU lost
// (< the injection, e.g. -1: never). Correct when every corner found it.
FaultOutcome score_ccu_kill(const FaultSpec& fault, const std::vector<double>& ccu_lost_s);

// "none", the finding's name, or "ccu_lost".
std::string diagnosis_name(const FaultOutcome& o);

// The CCU's reaction to a finding, as written in the report.
const char* reaction_to(Finding f);

// "load_cell_offset" -> Finding::LoadCellOffset ...; Finding::None for anything else.
Finding finding_from_name(const std::string& name);

}  // namespace bbw::faults
