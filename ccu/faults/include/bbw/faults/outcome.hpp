// Injected fault against what the CCU concluded, for summary.json's `faults` list
// (docs/faults.md, "Reporting"). Pure.
#pragma once

#include "bbw/faults/fault_monitor.hpp"
#include "bbw/faults/schedule.hpp"

namespace bbw::faults {

struct FaultOutcome {
  FaultSpec fault;
  bool detected = false;        // a diagnosis of this corner's part at or after the injection
  double detected_s = 0.0;
  double latency_ms = 0.0;      // detected_s - at_s
  Finding diagnosis = Finding::None;
  bool correct = false;         // the diagnosis names the injected part (on the right corner)
  const char* reaction = "none";
  double delivered_share = 0.0; // delivered / demanded total clamp force while it lasted (caller)
};

// What the corner's monitor concluded about `fault` (a corner fault). For a process kill a
// LinkLost diagnosis counts as detected but not as correct (the process was not named).
FaultOutcome assess(const FaultSpec& fault, const FaultMonitor& monitor);
// The CCU's reaction to a finding, as written in the report.
const char* reaction_to(Finding f);

}  // namespace bbw::faults
