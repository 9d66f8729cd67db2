// The corner's guard against a lost CCU (docs/faults.md, "CCU lost"). Pure: time is an
// argument. When no command has arrived for timeout_s, the corner holds the last command for
// hold_s, then moves to default_clamp_force_kN at ramp_kN_per_s and stays there until the CCU
// speaks again. It never releases: the default is > 0 by construction.
#pragma once

#include <optional>

namespace bbw::faults {

struct CcuWatchdogParams {
  double timeout_s = 0.02;               // no command for this long: the CCU is lost
  double hold_s = 0.5;                   // then hold the last command this long
  double default_clamp_force_kN = 8.0;   // then this clamp force (> 0: never release)
  double ramp_kN_per_s = 40.0;           // rate from the held command to the default
  // Time this corner itself did not run (on_own_stall) is not the CCU's silence: a corner cannot
  // take a command while it is not running. false: every second since the last command counts.
  bool exclude_own_stalls = true;

  void validate() const;  // throws std::invalid_argument naming the field, value and rule
};

enum class WatchdogMode {
  NoCommandYet,  // nothing received since start: the corner follows its own profile
  Normal,        // the CCU's command
  Holding,       // CCU lost: the last command, for at most hold_s
  Default,       // CCU lost for longer: the default clamp force (ramped)
};
const char* to_string(WatchdogMode m);

struct WatchdogOutput {
  WatchdogMode mode = WatchdogMode::NoCommandYet;
  std::optional<double> force_command_kN;  // empty only in NoCommandYet
};

class CcuWatchdog {
 public:
  explicit CcuWatchdog(const CcuWatchdogParams& params);  // throws std::invalid_argument

  // A command from the CCU arrived at time_s.
  void on_command(double time_s, double force_command_kN);
  // This corner did not run from from_s to to_s (realtime: a period begun late, the process
  // descheduled on a loaded machine; the same clock as on_command). Only the part after the last
  // command and after any stall already counted is subtracted from the CCU's silence: a stall
  // reported again as it is caught up (each late period reports its own lateness) counts once.
  void on_own_stall(double from_s, double to_s);
  // The command to apply at time_s. A function of time, the last command and the stalls since.
  WatchdogOutput at(double time_s) const;

  const CcuWatchdogParams& params() const { return p_; }

 private:
  CcuWatchdogParams p_;
  bool have_command_ = false;
  double last_command_s_ = 0.0;
  double last_force_kN_ = 0.0;
  double own_stall_s_ = 0.0;   // this corner's own stalls since the last command
  double stall_counted_to_s_ = 0.0;  // the end of the last stall counted
};

}  // namespace bbw::faults
