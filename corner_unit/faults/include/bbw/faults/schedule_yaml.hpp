// Strict reader of a scenario's `faults:` list (docs/faults.md, "Schedule"). Goes through the
// scenario loader's ExtraKeys hook, so a fault scenario is one file:
//
//   faults:
//     - {at_s: 7.0, corner: FL, part: load_cell, type: bias, bias_kN: 1.5, duration_s: 2.0}
//
// Any unknown key, missing parameter, type that does not belong to the part, or out-of-range
// value throws config::ConfigError naming the file, line, key path and rule.
#pragma once

#include <string>

#include "bbw/common/strict_yaml.hpp"
#include "bbw/faults/schedule.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::faults {

// Reads `faults:` from the top-level mapping if present (an absent key is an empty schedule).
FaultSchedule read_fault_schedule(config::Reader& top);

// An ExtraKeys hook that stores what read_fault_schedule() reads into `out`.
scenario::ExtraKeys fault_schedule_reader(FaultSchedule& out);

struct FaultScenario {
  scenario::Scenario scenario;
  FaultSchedule faults;
};

// Loads a scenario with its fault schedule and checks the schedule against it: every corner
// named must exist in the scenario, and every fault must start before the scenario ends.
FaultScenario load_fault_scenario(const std::string& file);
FaultScenario load_fault_scenario_string(const std::string& text, const std::string& name);
// The same checks on an already loaded pair (throws config::ConfigError).
void check_schedule(const scenario::Scenario& s, const FaultSchedule& faults);

}  // namespace bbw::faults
