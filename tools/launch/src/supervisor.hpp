// The launcher's supervisor: starts bbw_ccu and one bbw_corner per scenario corner, watches them
// (pidfds) within the run's wall-time bound, carries out the scenario's process faults (a process
// that froze itself at its scheduled kill is SIGKILLed; a corner may be restarted as a new
// incarnation), notices SIGINT/SIGTERM (through `stop_signal`, set by the launcher's
// SignalWatcher) and, when anything goes wrong, stops the others and says which process ended
// how. Also the one child before the run: scripts/bbw-keys.sh for --secure.
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "bbw/faults/link_faults.hpp"
#include "bbw/faults/schedule.hpp"
#include "bbw/runtime/child.hpp"
#include "bbw/scenario/scenario.hpp"
#include "partial_summary.hpp"

namespace bbw::launch {

using runtime::Child;
using runtime::Clock;
using runtime::ExitStatus;

struct RunPlan {
  const scenario::Scenario* scenario = nullptr;
  const faults::FaultSchedule* schedule = nullptr;
  std::string scenario_file, out_dir, mode, friction_feedback, run_id, keys_dir;
  int domain = 0;
  double discovery_s = 20.0;
  bool secure = false;
  // The processes to start, as the scenario declares them (LoadedRun::processes): "ccu"
  // (bbw_ccu), "ccu_standby" (bbw_ccu_standby, issue 16), a corner name (bbw_corner), "vehicle",
  // "pedal" (bbw_vehicle, bbw_pedal, issue 15).
  std::vector<std::string> processes;
  // A hot-standby CCU too (issue 16): bbw_ccu_standby (--role standby, logs and stats in
  // OUT/standby, output OUT/ccu_standby.out/.err); every process runs with --standby.
  bool standby = false;

  bool runs(const std::string& process) const;
};

struct SupervisedRun {
  std::string failure;                           // "" when every process ended as planned
  std::vector<ProcessEnd> processes;             // on a failure: how each ended
  std::map<std::string, unsigned> incarnations;  // corner -> processes started
  bool ccu_killed = false;                       // by the scenario's schedule (with a standby: both CCUs down)
  double ccu_killed_at_s = -1.0;
  std::string unreached_kill;                    // a scheduled kill never reached (an error)
};

class Supervisor {
 public:
  // `stop_signal`: 0, or the SIGINT/SIGTERM the launcher received.
  Supervisor(RunPlan plan, const std::atomic<int>& stop_signal);
  ~Supervisor();
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;

  // Starts every process; throws std::exception (after stopping what was started).
  void start();
  std::size_t processes() const { return children_.size(); }
  bool process_faults() const { return !actions_.empty(); }
  // Watches until every process has ended, a failure, a stop signal or the wall-time bound.
  SupervisedRun run();

 private:
  void spawn_corner(const std::string& corner, unsigned incarnation, double resume_at_s);

  RunPlan plan_;
  const std::atomic<int>& stop_signal_;
  std::vector<faults::ProcessAction> actions_;
  std::vector<std::string> profile_args_;
  std::string bin_, corner_bin_;
  std::vector<std::unique_ptr<Child>> children_;
  std::map<std::string, unsigned> incarnations_;
  Clock::time_point wall0_;
};

enum class KeysResult { Ready, Interrupted, Failed };

// --secure: the keys in `keys_dir` checked and, when a file is missing, created by
// scripts/bbw-keys.sh (BBW_LAUNCH_KEYS_SCRIPT replaces it: a test hook), its output in
// OUT/keys.out/.err. One launcher at a time per keys folder (an flock). A stop signal while the
// script runs stops it: Interrupted. `error` says why on Failed (`bad_keys`: the keys exist but
// are unusable, a configuration error).
KeysResult ensure_keys(const std::string& keys_dir, const std::string& out_dir, const std::atomic<int>& stop_signal,
                       std::string& error, bool& bad_keys);

}  // namespace bbw::launch
