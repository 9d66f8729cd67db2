#include "bbw/corner/command_gate.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bbw::corner {

void CommandGateParams::validate() const {
  if (!(max_force_kN > 0.0) || !std::isfinite(max_force_kN)) {
    throw std::invalid_argument("command gate: max_force_kN must be finite and > 0, got " + std::to_string(max_force_kN));
  }
  if (max_sources != 1 && max_sources != 2) {
    throw std::invalid_argument("command gate: max_sources must be 1 or 2, got " + std::to_string(max_sources));
  }
  if (!(max_rate_kN_per_s > 0.0) || !std::isfinite(max_rate_kN_per_s)) {
    throw std::invalid_argument("command gate: max_rate_kN_per_s must be finite and > 0, got " +
                                std::to_string(max_rate_kN_per_s));
  }
}

CommandGate::CommandGate(std::uint64_t run_id, const CommandGateParams& params) : run_id_(run_id), params_(params) {
  params_.validate();
}

GateResult CommandGate::check(const CommandSource& source, bool force_mode, double force_kN, double time_s) {
  GateResult r;
  if (source.run_id != run_id_) {
    ++counts_.refused_run;
    r.verdict = GateVerdict::RefusedRun;
    return r;
  }
  int index = -1;
  for (int i = 0; i < pinned_count_; ++i) {
    if (pinned_[static_cast<std::size_t>(i)] == source.writer) index = i;
  }
  if (index < 0 && (pinned_count_ == params_.max_sources || !source.announced_as_ccu)) {
    ++counts_.refused_source;
    r.verdict = GateVerdict::RefusedSource;
    return r;
  }
  if (force_mode && !std::isfinite(force_kN)) {
    ++counts_.refused_value;
    r.verdict = GateVerdict::RefusedValue;
    return r;
  }
  if (index < 0) {  // the first valid command of this run's CCU (or of its standby)
    index = pinned_count_++;
    pinned_[static_cast<std::size_t>(index)] = source.writer;
  }
  if (last_source_ >= 0 && index != last_source_ && last_force_kN_) {
    // A takeover: the other CCU's period clock is its own (realtime CCUs start theirs apart), so
    // the time between two writers' periods says nothing about the rate. The first command of
    // the new writer is limited to the rated range (one full-range period of rate).
    last_time_s_ = std::min(last_time_s_, time_s - params_.max_force_kN / params_.max_rate_kN_per_s);
  }
  last_source_ = index;
  if (!force_mode) {
    last_force_kN_ = 0.0;
    last_time_s_ = std::max(last_time_s_, time_s);
    ++counts_.accepted;
    r.force_kN = force_kN;
    return r;
  }
  double f = std::clamp(force_kN, 0.0, params_.max_force_kN);
  if (last_force_kN_) {
    const double step = params_.max_rate_kN_per_s * std::max(0.0, time_s - last_time_s_);
    f = std::clamp(f, *last_force_kN_ - step, *last_force_kN_ + step);
  }
  r.verdict = f == force_kN ? GateVerdict::Accepted : GateVerdict::Clamped;
  ++(r.verdict == GateVerdict::Accepted ? counts_.accepted : counts_.clamped);
  r.force_kN = f;
  last_force_kN_ = f;
  last_time_s_ = std::max(last_time_s_, time_s);
  return r;
}

}  // namespace bbw::corner
