// Whose commands a corner applied, with a hot-standby CCU (issue 16): every command the corner
// takes (DDS exclusive ownership already chose the writer) with the role of its writer, its
// period and the time it was taken. Pure: the adapter passes the role and both times in.
// Records the changes of writer and the longest gap between two commands, on the monotonic
// clock and in simulated time. No allocation after construction (at most kMaxSwitches changes
// are kept; more are counted).
#pragma once

#include <cstdint>

#include "bbw/runtime/failover_stats.hpp"

namespace bbw::runtime {

enum class CommandRole { Primary, Standby, Unknown };
const char* to_string(CommandRole r);

class CommandOwnerTracker {
 public:
  static constexpr std::size_t kMaxSwitches = 64;
  explicit CommandOwnerTracker(double period_s);

  // A command for period `step` (starting at `sim_s`) from `role`, taken at `mono_s`.
  void on_command(CommandRole role, std::uint64_t step, double sim_s, double mono_s);

  const runtime::CornerFailoverStats& stats() const { return stats_; }
  std::uint64_t switches_dropped() const { return dropped_; }
  bool have_command() const { return have_; }
  CommandRole owner() const { return owner_; }

 private:
  double period_s_;
  CornerFailoverStats stats_;
  bool have_ = false;
  CommandRole owner_ = CommandRole::Unknown;
  std::uint64_t last_step_ = 0;
  double last_mono_s_ = 0.0;
  std::uint64_t dropped_ = 0;
};

}  // namespace bbw::runtime
