// The summary of a run that did not finish: stopped by SIGINT/SIGTERM, or a process lost
// (killed, crashed, failed). Written from whatever each process logged before it ended, so a
// stop keeps its results; it names the processes that were lost and what is missing.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "bbw/dds/run_id.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::launch {

struct ProcessEnd {
  std::string name;              // "bbw_ccu", "bbw_corner FL", "bbw_corner FL.1"
  bool ended_by_itself = false;  // it had ended before the launcher stopped the others
  bool scheduled_kill = false;   // a process fault of the scenario (not a loss)
  bool ok = false;               // exit 0
  int exit_code = -1;            // -1 when killed by a signal
  std::string status;            // "exit 0", "killed by SIGKILL", ...
};

struct PartialRun {
  const scenario::Scenario* scenario = nullptr;
  std::string scenario_file, mode, run_id, out_dir, failure;
  int domain = 0;
  bool secure = false;
  bool interrupted = false;  // SIGINT or SIGTERM to the launcher
  int signal = 0;
  std::vector<ProcessEnd> processes;
  std::map<std::string, unsigned> incarnations;  // corner -> processes started
};

// Processes lost: ended by themselves, not ok, not a scheduled kill, and not simply stopped by
// the same signal as the launcher (exit 130/143 after an interrupt).
std::vector<std::string> lost_processes(const PartialRun& run);

// Writes OUT/summary.json ("complete": false, "interrupted", "failure", "lost_processes", per
// process its end, per corner what its stats and the CCU's log hold; null where nothing was
// logged). Returns the lost processes. Throws std::runtime_error when the file cannot be written.
std::vector<std::string> write_partial_summary(const PartialRun& run);

// The other bbw runs named in the `foreign_runs` entry of these stats files (missing files skipped).
std::vector<dds::PeerTag> foreign_runs_in(const std::vector<std::string>& stats_files);

}  // namespace bbw::launch
