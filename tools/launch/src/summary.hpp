// Run summary from the CCU's per-sample logs and the processes' stats files. Pure arithmetic
// over tables; the launcher reads the files.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "bbw/common/csv.hpp"
#include "bbw/faults/schedule.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::launch {

// Errors over no sample are NaN (written as null in summary.json), never 0: a reason says why
// (not_scored_reason, tracking_not_scored_reason).
struct CornerSummary {
  std::string corner;
  std::size_t samples = 0;
  std::size_t samples_scored = 0;          // after the first accepted fit, estimate valid
  double fused_max_abs_error_kN = 0.0;     // fused estimate vs plant truth
  double fused_rms_error_kN = 0.0;
  double compensated_max_abs_error_kN = 0.0;  // load cell minus friction vs truth
  double compensated_rms_error_kN = 0.0;
  double load_cell_rms_error_kN = 0.0;     // raw load cell vs truth, same samples
  std::size_t force_samples = 0;           // samples under a clamp-force command
  double tracking_rms_error_kN = 0.0;      // true clamp force vs command
  // Holds only: samples whose command has stayed within 0.05 kN for 0.3 s (step transients,
  // bounded by the actuator's speed, excluded) and is above 0.5 kN.
  double tracking_steady_max_abs_error_kN = 0.0;
  double tracking_steady_rms_error_kN = 0.0;
  std::size_t steady_samples = 0;
  double tracking_max_abs_error_kN = 0.0;
};

// Table columns used: time_s, force_internal_kN, force_true_kN, command, force_mode,
// estimate_kN, fused_kN, valid, calibrated (the CCU's ccu_<corner>.csv).
CornerSummary summarize_corner(const std::string& corner, const csv::Table& log);

csv::ReadOptions ccu_log_columns();

// Why the estimate errors are null ("" when samples were scored). `fits_accepted`: the CCU's
// count for the corner (a corner that was never calibrated has no valid estimate to score).
std::string not_scored_reason(const CornerSummary& s, long long fits_accepted);
// Why the tracking errors (all force-command samples, or the holds) are null ("" when both were scored).
std::string tracking_not_scored_reason(const CornerSummary& s);

// What the launcher knows of a run whose processes all ended as planned.
struct CompletedRun {
  const scenario::Scenario* scenario = nullptr;
  const faults::FaultSchedule* schedule = nullptr;
  std::string scenario_file, mode, run_id, out_dir, friction_feedback;
  int domain = 0;
  bool secure = false;
  bool report = true;                            // also write report.html
  std::map<std::string, unsigned> incarnations;  // corner -> processes started
  std::vector<std::string> processes;            // what the launcher started (the scenario's `processes:`)
  bool ended_by_injected_ccu_kill = false;
  double launch_wall_s = 0.0;
  // A run with a hot-standby CCU (issue 16): summary.json gets a `failover` object
  // (failover_summary.hpp), and the CCU logs and stats summarised are those of `ccu_dir` (the
  // CCU that ran to the end: OUT, or OUT/standby after the primary failed; "" = out_dir).
  bool standby = false;
  std::string ccu_dir;
};

// "" for a corner's first process, ".<n>" for its incarnation n (file and process names).
std::string incarnation_suffix(unsigned n);
// OUT/corner_<C>[.<n>].stats of a corner's incarnation n (0: the first process).
std::string corner_stats_file(const std::string& out_dir, const std::string& corner, unsigned incarnation);

// The totals the launcher prints at the end.
struct RunTotals {
  double simulated_s = 0.0, wall_s = 0.0;
  long long published = 0, received = 0, gaps = 0;
};

// Writes OUT/summary.json (complete run), OUT/timeline.csv and, if asked, OUT/report.html from
// the processes' stats files (bbw/runtime/run_stats.hpp) and logs. Errors over no sample are
// null with a reason, never 0. Throws std::runtime_error naming the file (and key) at fault.
RunTotals write_run_summary(const CompletedRun& run);

}  // namespace bbw::launch
