// Checks a scenario must pass before `./bbw run` (bbw_launch) or `./bbw simulate` starts
// anything: the corners of a four-corner DDS run, and the size of what the run would write and
// how long it would simulate. Pure functions of the loaded Scenario; each failure is a
// config::ConfigError naming the file, the line, the key and the rule (docs/security.md, "Inputs").
#pragma once

#include <cstdint>

#include "bbw/common/strict_yaml.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::scenario {

// Over DDS every corner is one of FL, FR, RL, RR, each at most once (the CCU's channels and the
// security identities are those four). Offline scenarios (the paper rig's T28 ... T54) are
// refused here with the first corner that is not one of them.
void check_four_corner_run(const Scenario& s);

// What a run of the scenario would produce, estimated from the scenario alone.
struct RunEstimate {
  double plant_steps = 0.0;     // duration_s / plant_dt_s, per corner
  double samples = 0.0;         // plant steps summed over the corners
  double output_bytes = 0.0;    // CSV written by ./bbw run (or ./bbw simulate, which writes less)
};

// Bytes per line the estimate assumes, rounded up from a 14 s four-corner lockstep run
// (load_cell_drift): the CCU's per-sample log ccu_FL.csv averages 255 bytes a line, the period
// logs corner_FL_periods.csv 28 and ccu_periods.csv 61.
constexpr double kBytesPerSampleLine = 260.0;
constexpr double kBytesPerPeriodLine = 64.0;

RunEstimate estimate_run(const Scenario& s);

struct RunLimits {
  double max_output_bytes = 2.0e9;   // 2 GB of CSV
  double max_duration_s = 3600.0;    // one hour of simulated time
};

// Throws ConfigError (key duration_s, or plant_dt_s for the output) when the estimate passes a
// limit; the message gives the estimate, the limit and that --allow-large accepts it.
void check_run_size(const Scenario& s, const RunLimits& limits = {});

}  // namespace bbw::scenario
