// Whether a realtime standby run was decided by the machine rather than by the CCUs, shared by
// the failover tests over one host (test_failover_runs.cpp) and across network namespaces
// (test_failover_netns.cpp): both repeat such a run (at most twice, with a note naming the stall),
// as they repeat Fast DDS's own aborts.
#pragma once

#include <algorithm>
#include <string>

#include "bbw/runtime/failover_stats.hpp"

namespace bbw::system_test {

// From the CCUs' own stall intervals (their failover stats: their sends further apart than the
// corners' deadline): the standby stalled within the takeover window (25 ms from the failure at
// failed_mono_s, the goals' longest figure; none when negative), or both CCUs stalled at once
// (the corners then hear nobody, and no standby can help), or, while the corners could hear the
// standby alone (from the failure to alone_until_mono_s; none when not after it), the standby
// stalled for the corners' watchdog timeout less a period (min_alone_stall_s): the corners'
// only CCU silent past their watchdog, which then does what it is for (a -j2 system pass: the
// link cut's corners 25 ms without a command, their safe state entered, the standby 1 stall).
// Returns what happened, or "".
inline std::string ccus_starved(const runtime::CcuFailoverStats& primary, const runtime::CcuFailoverStats& standby,
                                double failed_mono_s, double alone_until_mono_s = -1.0, double min_alone_stall_s = 0.015) {
  auto ms = [](double s) { return std::to_string(1e3 * s); };
  if (failed_mono_s >= 0.0) {
    const double from = failed_mono_s, to = from + 0.025;
    for (const auto& st : standby.stall_intervals) {
      if (st.to_mono_s >= from && st.from_mono_s <= to) {
        return "the standby stalled from " + ms(st.from_mono_s - from) + " to " + ms(st.to_mono_s - from) +
               " ms after the primary's failure (starved of the CPU)";
      }
      if (st.to_mono_s >= from && st.from_mono_s <= alone_until_mono_s && st.to_mono_s - st.from_mono_s >= min_alone_stall_s) {
        return "the standby, the only CCU the corners could hear, stalled from " + ms(st.from_mono_s - from) + " to " +
               ms(st.to_mono_s - from) + " ms after the primary's failure (starved of the CPU)";
      }
    }
  }
  for (const auto& a : primary.stall_intervals) {
    for (const auto& b : standby.stall_intervals) {
      if (a.to_mono_s >= b.from_mono_s && b.to_mono_s >= a.from_mono_s) {
        return "both CCUs stalled at once, " + ms(std::max(a.from_mono_s, b.from_mono_s) - primary.t0_mono_s) + " to " +
               ms(std::min(a.to_mono_s, b.to_mono_s) - primary.t0_mono_s) + " ms into the run (starved of the CPU)";
      }
    }
  }
  return "";
}

}  // namespace bbw::system_test
