// The `faults` part of a run's summary (docs/faults.md, "Reporting"): each injected fault against
// the detections the CCU logged (ccu.stats) or, for a CCU kill, the corners' watchdogs; and the
// total clamp force against the demand (corner_<C>_periods.csv). Pure arithmetic over what the
// launcher read.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "bbw/faults/outcome.hpp"
#include "bbw/faults/schedule.hpp"
#include "bbw/runtime/run_stats.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::launch {

// A detection of the CCU's fault monitor as ccu.stats holds it (bbw/runtime/run_stats.hpp).
using Detection = runtime::DetectionStats;

struct TimelinePoint {
  double time_s = 0.0;          // end of the period
  double demand_kN = 0.0;       // demanded total clamp force (the scenario's nominal split)
  double delivered_kN = 0.0;    // sum of the corners' true clamp forces (a dead corner: 0)
};

// One point per CCU period. `period_logs`: per corner, the rows (time_s, force_true_kN) of its
// corner_<C>_periods.csv, all incarnations.
std::vector<TimelinePoint> build_timeline(const scenario::Scenario& s,
                                          const std::vector<std::vector<std::pair<double, double>>>& period_logs);

// Scored by the one fault scorer (bbw/faults/outcome.hpp), shared with the closed-loop tests.
using FaultResult = faults::FaultOutcome;

// ccu.stats' detections, typed. Throws std::runtime_error on a corner or finding bbw does not know.
std::vector<faults::DetectionEvent> detection_events(const std::vector<Detection>& detections);
// The detections no injected fault explains (faults::score_run): false alarms.
std::vector<faults::DetectionEvent> false_alarms(const faults::FaultSchedule& schedule, const std::vector<Detection>& detections);

// ccu_lost_s: per corner, the simulated time its watchdog found the CCU lost (< 0: never).
// Throws std::runtime_error on a detection whose corner or finding bbw does not know.
std::vector<FaultResult> assess_faults(const faults::FaultSchedule& schedule, const std::vector<Detection>& detections,
                                       const std::map<std::string, double>& ccu_lost_s,
                                       const std::vector<TimelinePoint>& timeline, double run_end_s);

}  // namespace bbw::launch
