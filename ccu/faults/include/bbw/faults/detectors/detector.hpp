// What every detector of the fault monitor sees (docs/faults.md, "Detection"): the sample, the
// sample before it (continuity is broken after a link or process loss), the guard's verdict, and
// the arbiter to confirm findings to and to ask which parts are still trusted. One detector per
// fault family, each with its parameters (MonitorParams, loaded from config/faults/monitor.yaml);
// pure, no allocation per sample.
#pragma once

#include "bbw/faults/arbiter.hpp"
#include "bbw/faults/reading.hpp"
#include "bbw/faults/sample_guard.hpp"

namespace bbw::faults {

struct MonitorParams;

struct SampleContext {
  const CornerReading& r;
  const SampleCheck& check;
  bool have_prev;             // `prev` is the previous usable sample of this corner
  const CornerReading& prev;
  bool prev_load_cell_present;
  double dt_s;                // r.time_s - prev.time_s (0 without a previous sample)
};

}  // namespace bbw::faults
