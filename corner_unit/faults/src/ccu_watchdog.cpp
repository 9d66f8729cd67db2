#include "bbw/faults/ccu_watchdog.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bbw::faults {
namespace {

void require(bool ok, const char* field, double value, const char* rule) {
  if (!ok) throw std::invalid_argument(std::string("CcuWatchdogParams.") + field + " = " + std::to_string(value) + ": " + rule);
}

}  // namespace

void CcuWatchdogParams::validate() const {
  require(timeout_s > 0.0 && std::isfinite(timeout_s), "timeout_s", timeout_s, "must be > 0");
  require(hold_s >= 0.0 && std::isfinite(hold_s), "hold_s", hold_s, "must be >= 0");
  require(default_clamp_force_kN > 0.0 && std::isfinite(default_clamp_force_kN), "default_clamp_force_kN",
          default_clamp_force_kN, "must be > 0 (the safe state never releases the brake)");
  require(ramp_kN_per_s > 0.0 && std::isfinite(ramp_kN_per_s), "ramp_kN_per_s", ramp_kN_per_s, "must be > 0");
}

const char* to_string(WatchdogMode m) {
  switch (m) {
    case WatchdogMode::NoCommandYet: return "no_command_yet";
    case WatchdogMode::Normal: return "normal";
    case WatchdogMode::Holding: return "holding";
    case WatchdogMode::Default: return "default";
  }
  return "?";
}

CcuWatchdog::CcuWatchdog(const CcuWatchdogParams& params) : p_((params.validate(), params)) {}

void CcuWatchdog::on_command(double time_s, double force_command_kN) {
  if (!std::isfinite(force_command_kN) || !std::isfinite(time_s)) return;  // never act on a corrupt command
  if (have_command_ && time_s < last_command_s_) return;                   // an old command arriving late
  have_command_ = true;
  last_command_s_ = time_s;
  last_force_kN_ = force_command_kN;
  own_stall_s_ = 0.0;
}

void CcuWatchdog::on_own_stall(double from_s, double to_s) {
  if (!p_.exclude_own_stalls || !have_command_ || !std::isfinite(from_s) || !std::isfinite(to_s)) return;
  const double from = std::max({from_s, last_command_s_, stall_counted_to_s_});
  if (to_s <= from) return;
  own_stall_s_ += to_s - from;
  stall_counted_to_s_ = to_s;
}

WatchdogOutput CcuWatchdog::at(double time_s) const {
  if (!have_command_) return {};
  const double silent_s = time_s - last_command_s_ - own_stall_s_;
  if (silent_s < p_.timeout_s) return {WatchdogMode::Normal, last_force_kN_};
  const double default_from_s = p_.timeout_s + p_.hold_s;
  if (silent_s < default_from_s) return {WatchdogMode::Holding, last_force_kN_};
  // Ramp from the held command to the default.
  const double step_kN = p_.ramp_kN_per_s * (silent_s - default_from_s);
  const double target = p_.default_clamp_force_kN;
  const double f = last_force_kN_ < target ? std::min(target, last_force_kN_ + step_kN)
                                           : std::max(target, last_force_kN_ - step_kN);
  return {WatchdogMode::Default, f};
}

}  // namespace bbw::faults
