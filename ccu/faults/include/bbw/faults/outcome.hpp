// The one fault scorer (docs/faults.md, "Reporting"): each injected fault against what was
// detected, used by bbw_launch (summary.json's `faults` list, from ccu.stats) and by the
// closed-loop tests (tests/faults, from CcuNode::detections()). Pure.
#pragma once

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
  bool detected = false;        // anything detected on the faulty corner at or after the injection
  double detected_s = 0.0;      // the first such detection (CCU kill: the first watchdog)
  double latency_ms = 0.0;      // detected_s - at_s
  double diagnosis_s = 0.0;     // when the diagnosis below was made (the right part's, if any)
  double diagnosis_latency_ms = 0.0;
  Finding diagnosis = Finding::None;  // the diagnosed part's final finding
  bool ccu_lost = false;        // CCU kill: the diagnosis is the corners' "CCU lost"
  bool correct = false;         // the diagnosis names the injected part (CCU kill: every corner saw it)
  const char* reaction = "none";
  double delivered_share = 1.0; // delivered / demanded total clamp force while it lasted (caller)
};

// A corner fault against the detections (any order): the diagnosis prefers the injected part
// (a process kill: Part::Process), then the earliest; a later finding of the same part refines
// it (actuator_lost -> actuator_not_releasing). A wrong part is a detection, not a correct one.
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
