// Loop check (issue 14): does a corner's local force loop hold a steady clamp force? Runs a
// fault-free scenario through the real node cores over the in-memory transport
// (node::InProcessRun, as `bbw_campaign run --transport memory` does) and measures, per corner,
// the oscillation while the command is held: the RMS of the high-passed true clamp force and
// motor current, the true force's peak-to-peak, the largest load-cell step between two samples,
// and the findings the fault monitor raised (every finding of a fault-free run is false).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "bbw/calibration/config.hpp"
#include "bbw/faults/fault_monitor.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::loop_check {

struct HoldOptions {
  double settle_s = 0.3;            // a hold starts this long after the command stopped changing
  double min_command_kN = 1.0;      // holds below this are not counted (released or touching)
  double high_pass_s = 0.02;        // high-pass time constant (first order) of force and current
};

struct CornerLoopStats {
  std::string corner;
  double hold_s = 0.0;              // time in holds
  double force_hp_rms_kN = 0.0;     // RMS of the high-passed true clamp force in holds
  double force_pp_kN = 0.0;         // largest peak-to-peak of the true clamp force within one hold
  double current_hp_rms_A = 0.0;    // RMS of the high-passed motor current in holds
  double load_cell_step_kN = 0.0;   // largest |load-cell change| between two samples in holds
  double hold_error_rms_kN = 0.0;   // RMS of (command - true clamp force) in holds
  std::vector<std::string> findings;  // "load_cell_noisy at 12.345 s"
};

struct LoopReport {
  std::vector<CornerLoopStats> corners;
  double worst_force_hp_rms_kN() const;
  std::size_t findings() const;
};

// Throws std::invalid_argument (a scenario the in-process runner refuses).
LoopReport measure(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
                   const faults::MonitorParams& monitor, const HoldOptions& options = {});

}  // namespace bbw::loop_check
