#include "bbw/runtime/command_owner.hpp"

#include <stdexcept>
#include <utility>

namespace bbw::runtime {

const char* to_string(CommandRole r) {
  switch (r) {
    case CommandRole::Primary: return "primary";
    case CommandRole::Standby: return "standby";
    case CommandRole::Unknown: return "unknown";
  }
  return "unknown";
}

CommandOwnerTracker::CommandOwnerTracker(double period_s, bool lockstep) : period_s_(period_s), lockstep_(lockstep) {
  if (!(period_s > 0.0)) throw std::invalid_argument("CommandOwnerTracker: period_s must be > 0");
  stats_.switches.reserve(kKeepFirst);
}

CornerFailoverStats CommandOwnerTracker::stats() const {
  CornerFailoverStats s = stats_;
  for (std::size_t i = 0; i < last_count_; ++i) s.switches.push_back(last_[(last_head_ + i) % kKeepLast]);
  return s;
}

void CommandOwnerTracker::on_command(CommandRole role, std::uint64_t step, double sim_s, double mono_s) {
  switch (role) {
    case CommandRole::Primary: ++stats_.commands_primary; break;
    case CommandRole::Standby: ++stats_.commands_standby; break;
    case CommandRole::Unknown: ++stats_.commands_unknown; break;
  }
  if (have_ && lockstep_ && step <= last_step_) return;  // a repeated grant: counted above, no change
  if (!have_ || role != owner_) {
    OwnerSwitch x{have_ ? to_string(owner_) : "none", to_string(role), step, sim_s, mono_s,
                  have_ ? 1e3 * (mono_s - last_mono_s_) : 0.0};
    if (stats_.switches.size() < kKeepFirst) {
      stats_.switches.push_back(std::move(x));
    } else if (last_count_ < kKeepLast) {
      last_[(last_head_ + last_count_++) % kKeepLast] = std::move(x);
    } else {
      last_[last_head_] = std::move(x);  // the oldest of the ring goes
      last_head_ = (last_head_ + 1) % kKeepLast;
      ++stats_.switches_dropped;
    }
  }
  if (have_) {
    const double gap_mono_ms = 1e3 * (mono_s - last_mono_s_);
    if (gap_mono_ms > stats_.max_gap_mono_ms) {
      stats_.max_gap_mono_ms = gap_mono_ms;
      stats_.max_gap_mono_at_sim_s = sim_s;
    }
    if (step > last_step_) {
      const double gap_sim_ms = 1e3 * period_s_ * static_cast<double>(step - last_step_);
      if (gap_sim_ms > stats_.max_gap_sim_ms) {
        stats_.max_gap_sim_ms = gap_sim_ms;
        stats_.max_gap_sim_at_s = sim_s;
      }
    }
  }
  if (!have_ || step > last_step_) last_step_ = step;
  have_ = true;
  owner_ = role;
  last_mono_s_ = mono_s;
  stats_.last_command_mono_s = mono_s;
}

}  // namespace bbw::runtime
