// What a run with a hot-standby CCU (issue 16, docs/faults.md "Hot-standby CCU") leaves for
// bbw_launch and the tests besides the usual stats: each CCU's role, strength and failure, and
// each corner's record of whose commands it applied. One serialiser/parser pair, "key=value"
// per line like run_stats.hpp; a missing or malformed key is an error naming the file and key.
//
// Times: `*_sim_s` are simulated seconds; `*_mono_s` are CLOCK_MONOTONIC seconds
// (std::chrono::steady_clock since its epoch), one clock for every process on this host (also in
// network namespaces), so a failure in one process and a takeover in another can be subtracted.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace bbw::runtime {

// steady_clock now, in seconds since its epoch (CLOCK_MONOTONIC).
double mono_now_s();

// One of a CCU's own stalls: two consecutive sends further apart than the command deadline.
struct StallInterval {
  double from_mono_s = 0.0;  // the send before the stall
  double to_mono_s = 0.0;    // when the CCU ran again (its next send follows at once)
};

struct CcuFailoverStats {
  static constexpr std::size_t kMaxStallIntervals = 64;  // the first ones are kept; `stalls` counts all
  std::string role;                  // primary | standby
  std::uint32_t strength_initial = 0;
  std::uint32_t strength_final = 0;
  std::string failure;               // "" | kill | hang: the scheduled failure this process carried out
  double failed_sim_s = -1.0;        // the simulated time it froze at (-1: never)
  double failed_mono_s = -1.0;
  double resumed_mono_s = -1.0;      // continued after the hang (-1: never)
  std::uint32_t outages = 0;         // times it lowered its strength (stopped and continued, or cut off)
  std::uint32_t stalls = 0;          // realtime: its own commands further apart than the command deadline
  std::vector<StallInterval> stall_intervals;  // the first kMaxStallIntervals of them, in order
  double demoted_sim_s = -1.0;       // the last time it did (-1: never)
  double demoted_mono_s = -1.0;
  std::string demote_reason;         // the last reason: "" | resumed after a stop | cut off from every corner (realtime) | left the lock step
  std::uint64_t periods_done = 0;
  double t0_mono_s = -1.0;           // realtime: when its simulated time was 0 (its clock's start)
};

// One change of the writer a corner obeys (what DDS exclusive ownership let through).
struct OwnerSwitch {
  std::string from, to;     // primary | standby | unknown | none (before the first command)
  std::uint64_t step = 0;   // the command's period
  double sim_s = 0.0;       // the period's start (simulated)
  double mono_s = 0.0;      // when the corner took it (realtime: applied at once)
  double gap_ms = 0.0;      // since the command before it was taken (monotonic)
};

struct CornerFailoverStats {
  std::string corner;
  std::uint64_t commands_primary = 0;
  std::uint64_t commands_standby = 0;
  std::uint64_t commands_unknown = 0;
  std::uint64_t commands_stale = 0;     // realtime: dropped, written more than 50 ms before they arrived
  // Longest time between two consecutive commands taken, after the first: on the monotonic
  // clock (what a realtime corner lives by) and in simulated periods (lockstep's time).
  double max_gap_mono_ms = 0.0;
  double max_gap_mono_at_sim_s = -1.0;  // the period start of the command that ended it
  double max_gap_sim_ms = 0.0;
  double max_gap_sim_at_s = -1.0;
  double last_command_mono_s = -1.0;
  // Realtime: the corner's own stalls (a period begun later than the command deadline), merged
  // where the late periods of one stall overlap; the first kMaxStallIntervals kept, all counted.
  std::uint32_t stalls = 0;
  std::vector<StallInterval> stall_intervals;
  std::vector<OwnerSwitch> switches;    // in order; the first is none -> the first owner
  // Changes not kept, all between switches[CommandOwnerTracker::kKeepFirst - 1] and the next.
  std::uint64_t switches_dropped = 0;
};

// A corner's period began late_s late at now_mono_s: a stall from now - late to now, merged into
// the last one where they overlap (a stall's late periods are caught up one after another).
void note_corner_stall(CornerFailoverStats& s, double late_s, double now_mono_s);

std::string to_text(const CcuFailoverStats& s);
std::string to_text(const CornerFailoverStats& s);
CcuFailoverStats parse_ccu_failover(const std::string& text, const std::string& file);
CornerFailoverStats parse_corner_failover(const std::string& text, const std::string& file);
void save(const CcuFailoverStats& s, const std::string& file);
void save(const CornerFailoverStats& s, const std::string& file);
CcuFailoverStats load_ccu_failover(const std::string& file);
CornerFailoverStats load_corner_failover(const std::string& file);

}  // namespace bbw::runtime
