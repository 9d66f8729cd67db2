// The `failover` object of summary.json for a run with a hot-standby CCU (issue 16,
// docs/faults.md "Hot-standby CCU"): from the two CCUs' and the corners' failover stats and the
// corners' period logs. Pure arithmetic; the launcher (and the netns test) read the files.
//
// Definitions:
//   failed_s / failed mono time: when the primary froze (its scheduled kill or hang), or, for a
//     link cut, when the test took its link down (the caller passes it).
//   takeover: per corner, the first command from the standby taken at or after the failure (a
//     realtime corner applies it in the period it takes it); the run's takeover is the slowest
//     corner's. Realtime: takeover_ms on the monotonic clock. Lockstep: simulated time stands
//     still while the corners wait, so takeover_ms is simulated (the period the standby's first
//     command is for, minus failed_s) and takeover_wall_ms says how long the wait took.
//   max_command_gap_ms: the longest time between two consecutive commands at any corner over
//     the whole run (realtime: monotonic; lockstep: simulated, wall in max_command_gap_wall_ms);
//     takeover_gap_ms: the same at the takeover only (monotonic), the failover's own gap.
//   max_force_dip_kN: how far any corner's tracking error (planned demand - true clamp force)
//     rose in the periods ending in (failed_s, failed_s + kDipWindow_s] above its mean over the
//     kDipReference_s before the failure (tracking_error_before_kN, the largest such mean: a
//     corner's standing error is not the failover's doing).
//   safe_state_entered: a corner's watchdog found the CCU lost (hold, then default force).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "bbw/common/json.hpp"
#include "bbw/runtime/failover_stats.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::launch {

inline constexpr double kDipWindow_s = 0.5;
inline constexpr double kDipReference_s = 0.05;

struct FailoverCornerInput {
  runtime::CornerFailoverStats owners;
  double ccu_lost_s = -1.0;                               // the corner's watchdog (-1: never)
  std::vector<std::pair<double, double>> periods;         // (period end time_s, force_true_kN)
};

struct FailoverInput {
  const scenario::Scenario* scenario = nullptr;
  bool lockstep = true;
  runtime::CcuFailoverStats primary, standby;
  std::vector<FailoverCornerInput> corners;               // in scenario order
  // The failure when the processes did not record it (a link cut made by a test): sim and mono.
  double failed_sim_s = -1.0, failed_mono_s = -1.0;
  std::string failure;                                    // kill | hang | link_cut
};

struct FailoverResult {
  std::string failure;                  // what failed first ("" when nothing did)
  double failed_s = -1.0;
  double takeover_s = -1.0;             // -1: no takeover
  double takeover_ms = -1.0;
  double takeover_wall_ms = -1.0;       // lockstep: the wall-clock wait; realtime: = takeover_ms
  std::string takeover_missing;         // corners that never took a standby command after it
  std::string owners_at_end;            // each corner's last owner, in scenario order (comma-separated)
  int corners_already_on_standby = 0;   // the owner was the standby before the failure
  double max_command_gap_ms = 0.0;
  double max_command_gap_wall_ms = 0.0;
  double takeover_gap_ms = -1.0;        // the slowest corner's gap between the last command before
                                        // the takeover and the standby's first (monotonic)
  double max_force_dip_kN = 0.0;
  double max_tracking_error_before_kN = 0.0;
  bool safe_state_entered = false;
  double safe_state_s = -1.0;
  int switches_before_failure = 0;      // owner changes before the failure (not the start's settling)
  int switches_after_failure = 0;       // ... at or after it (1 per corner: a clean takeover)
  int switches_back_to_primary = 0;     // after the failure, to the primary (flapping)
  long long commands_stale = 0;         // realtime: commands the corners dropped as too old
  double demoted_s = -1.0;              // the primary last lowered its strength (hand-back policy)
  std::string demote_reason;            // ... and why
  int primary_outages = 0, standby_outages = 0;  // stopped and continued, or cut off (hand-back rule)
  int primary_stalls = 0, standby_stalls = 0;    // commands further apart than the command deadline
  double standby_failed_s = -1.0;       // the standby's own failure (both lost)
};

// The input from a run's output folder: OUT/ccu_failover.stats, OUT/standby/ccu_failover.stats,
// OUT/corner_<C>_failover.stats, OUT/corner_<C>.stats (the watchdog) and OUT/corner_<C>_periods.csv
// of the scenario's corners (first incarnations). Throws std::runtime_error naming the file.
FailoverInput load_failover_input(const scenario::Scenario& scenario, const std::string& out_dir, bool lockstep);

FailoverResult assess_failover(const FailoverInput& in);
// Writes key "failover" into the open object of `j`.
void write_failover(json::Writer& j, const FailoverResult& r);

}  // namespace bbw::launch
