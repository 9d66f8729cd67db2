// Whose commands a corner applied, with a hot-standby CCU (issue 16): every command the corner
// takes (DDS exclusive ownership already chose the writer) with the role of its writer, its
// period and the time it was taken. Pure: the adapter passes the role and both times in.
// Records the changes of writer and the longest gap between two commands, on the monotonic
// clock and in simulated time. No allocation after construction: the first kKeepFirst changes and
// the last kKeepLast are kept, those between are counted (`switches_dropped`). A loaded machine
// makes lockstep ownership flap hundreds of times before a failure; the changes at and after the
// failure are the ones a takeover is measured by (with only the first 64 kept, a secure lockstep
// kill run under six busy loops reported its takeover missing: 250 changes before the kill).
#pragma once

#include <array>
#include <cstdint>

#include "bbw/runtime/failover_stats.hpp"

namespace bbw::runtime {

enum class CommandRole { Primary, Standby, Unknown };
const char* to_string(CommandRole r);

class CommandOwnerTracker {
 public:
  static constexpr std::size_t kKeepFirst = 32;
  static constexpr std::size_t kKeepLast = 96;
  // lockstep: a command for a period not after the latest one taken repeats a grant the corner
  // already obeyed (the two CCUs' grants are the same; a corner takes it again, harmlessly): it is
  // counted by its writer's role but is no change of owner. (Counted as one, the standby's repeat
  // of period 699, taken 54 ms after the primary was killed at its period 700, gave a takeover
  // 5 ms before the failure.) Realtime: a takeover's command may name an earlier period (the two
  // CCUs' clocks start apart), so every change of writer is one.
  explicit CommandOwnerTracker(double period_s, bool lockstep = false);

  // A command for period `step` (starting at `sim_s`) from `role`, taken at `mono_s`.
  void on_command(CommandRole role, std::uint64_t step, double sim_s, double mono_s);

  // The counts and gaps, and the kept changes in order (switches_dropped: how many between).
  runtime::CornerFailoverStats stats() const;
  bool have_command() const { return have_; }
  CommandRole owner() const { return owner_; }

 private:
  double period_s_;
  bool lockstep_;
  CornerFailoverStats stats_;
  bool have_ = false;
  CommandRole owner_ = CommandRole::Unknown;
  std::uint64_t last_step_ = 0;
  double last_mono_s_ = 0.0;
  std::array<OwnerSwitch, kKeepLast> last_{};  // ring of the latest changes after the first kKeepFirst
  std::size_t last_head_ = 0, last_count_ = 0;
};

}  // namespace bbw::runtime
