// One campaign run's result: its faults scored by the one scorer (bbw/faults/outcome.hpp), its
// false alarms, and the harm each fault did while undetected, from the run's logs; written to
// result.json atomically (a temporary file renamed), read back by the report.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "bbw/faults/outcome.hpp"
#include "bbw/faults/schedule.hpp"

namespace bbw::campaign {

struct FaultRow {
  std::string kind;         // spec.hpp FaultKind name
  std::string onset;        // Onset name
  std::string corner;
  double at_s = 0.0;
  double end_s = 0.0;       // the fault's end (or the run's)
  double magnitude = 0.0;   // in the kind's unit (draw.hpp); 0 for kinds without one
  bool above_limit = true;  // |magnitude| >= the stated detectability limit
  bool masked = false;       // another fault on its corner hid it until it ended (faults::observable_from)
  double observable_s = 0.0; // when it could first show (its window and latency run from here)
  bool detected = false;
  bool correct = false;
  double latency_ms = -1.0;
  std::string diagnosis;
  double window_s = 0.0;
  // Harm while undetected (from the injection to the detection, or to the fault's end):
  double harm_force_error_kN = 0.0;     // max |true clamp force - command| on the corner
  double harm_estimate_error_kN = 0.0;  // max |CCU's force estimate - true clamp force|
  // After the detection (to the run's end): max |CCU's force estimate - true clamp force| where
  // the CCU has one, the estimate the reaction leaves the brake with (a lost load cell's curve, a
  // faulty resolver's load cell). NaN when undetected, or in a result written before it existed.
  double after_estimate_error_kN = std::numeric_limits<double>::quiet_NaN();
};

struct FalseAlarmRow {
  std::string corner;
  std::string finding;
  double detected_s = 0.0;
};

struct RunResult {
  int index = 0;
  bool fault_free = true;
  std::string profile;
  std::string transport;
  std::string host;           // the GNU parallel sshlogin that ran it (":" this host)
  double duration_s = 0.0;
  double wall_s = 0.0;
  bool ok = true;             // the run itself completed (else `error`)
  std::string error;
  std::vector<FaultRow> faults;
  std::vector<FalseAlarmRow> false_alarms;
};

// The rows for a finished run: `out_dir` holds the CCU's logs ccu_<corner>.csv; detections as
// the scorer takes them. Throws std::runtime_error on an unreadable log.
void score_into(RunResult& r, const std::vector<faults::FaultSpec>& faults, const std::vector<std::string>& kinds,
                const std::vector<std::string>& onsets, const std::vector<faults::DetectionEvent>& detections,
                const std::string& out_dir, double run_end_s);

void save_result(const RunResult& r, const std::string& file);  // atomic: file.tmp, then rename
RunResult load_result(const std::string& file);                  // throws std::runtime_error naming the file

}  // namespace bbw::campaign
