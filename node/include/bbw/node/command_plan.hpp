// Pure CCU logic: what each corner is told to do at a time, and how the clamp-force estimate
// is fused. No DDS, no clock: time is an argument.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/scenario/profile.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::ccu {

enum class CommandMode { Profile, Force };

struct PlannedCommand {
  CommandMode mode = CommandMode::Profile;
  double clamp_force_kN = 0.0;  // Force mode
};

// Turns the scenario's pedal demand into per-corner clamp-force commands (front/rear split
// from DemandSpec). Corners driven by their own profile (test rig, force profile) are told to
// follow it.
class CommandPlanner {
 public:
  explicit CommandPlanner(const scenario::Scenario& scenario);  // throws std::invalid_argument
  PlannedCommand at(std::size_t corner_index, double time_s) const;

 private:
  std::vector<scenario::DriveMode> modes_;
  std::vector<double> axle_factor_;
  double max_clamp_force_kN_ = 0.0;
  std::optional<scenario::BreakpointProfile> demand_;
};

}  // namespace bbw::ccu
