// The closed loop for fault tests: the node cores the processes run (node::InProcessRun: the
// CcuNode with CcuCore, its CornerSupervisors, calibrators and Redistributor; one CornerNode per
// corner with its watchdog, friction tracker, fault injector and link faults) over the in-memory
// transport, in lockstep, with the schedule's process faults carried out as over DDS. This file
// only records what the nodes did, period by period, and sums it up; it decides nothing.
#pragma once

#include <bbw/idl/bbw_msgs.h>

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "bbw/calibration/config.hpp"
#include "bbw/faults/ccu_watchdog.hpp"
#include "bbw/faults/fault_monitor.hpp"
#include "bbw/faults/outcome.hpp"
#include "bbw/faults/reading.hpp"
#include "bbw/faults/redistributor.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/scenario/corner_sim.hpp"

namespace bbw::faults::test {

std::string source_path(const std::string& rel);

// What the CCU reads from a simulated corner's sample: the corner's wire conversion
// (dds::to_msg, into `wire`) followed by the CCU's (node::reading_from), the path every sample
// takes. `wire` is the caller's, made once (a message's constructor allocates).
CornerReading reading_from(const scenario::CornerSample& s, msg::MeasurementSample& wire);

struct LoopOptions {
  calibration::CalibratorConfig calibrator;
  MonitorParams monitor;          // actuator model fields are taken from the scenario's plant
  CcuWatchdogParams watchdog;
  bool redistribute = true;          // false: the CCU keeps the nominal split (for comparison)
  bool count_held_force = true;      // false: a corner that does not release counts as braking 0
  // A hostile link: called for every sample a corner sends (corner = slot, 0 FL .. 3 RR); fills
  // `out` with what reaches the CCU in its place (default: the sample itself).
  std::function<void(std::size_t corner, const msg::MeasurementSample& s, std::vector<msg::MeasurementSample>& out)>
      deliver;
};

LoopOptions default_options();

struct PeriodRecord {
  double time_s = 0.0;                    // end of the period
  double demand_total_kN = 0.0;           // demanded total clamp force (the CCU's demand at the period's start)
  double delivered_total_kN = 0.0;        // sum of the true clamp forces of the corners that ran the period
  std::array<double, kCorners> true_kN{};      // NaN: the corner did not run this period (dead process)
  std::array<double, kCorners> estimate_kN{};  // NaN when the CCU is down
  std::array<double, kCorners> command_kN{};  // what the CCU asked for (NaN when the CCU is down)
  std::array<double, kCorners> applied_kN{};  // what the corner followed (watchdog output; NaN: none)
  std::array<bool, kCorners> available{};
  std::array<double, kCorners> residual_kN{};  // the monitor's last analytic-redundancy residual
  std::array<double, kCorners> noise_kN{};
  std::array<double, kCorners> residual_change_kN{};
  bool ccu_alive = true;
};

struct LoopResult {
  std::vector<PeriodRecord> periods;
  std::vector<FaultOutcome> outcomes;     // one per corner fault in the schedule
  std::array<std::uint64_t, kCorners> guard_rejected{};
  std::array<std::uint64_t, kCorners> calibrator_samples{};
  std::array<std::uint64_t, kCorners> calibrator_restarts{};
  std::array<std::uint64_t, kCorners> fits{};
  std::array<Diagnosis, 5 * kCorners> diagnoses{};  // [corner * 5 + part]
  std::size_t faults_raised() const;                 // diagnoses present, all corners and parts
};

LoopResult run_closed_loop(const FaultScenario& fs, const LoopOptions& options);

// The first time after t_from at which the delivered total is at least `fraction` of the
// achievable demand (min(demand, sum of the available corners' limits)) and stays so until
// t_to; -1 if never.
double recovery_time_s(const LoopResult& r, double fraction, double t_from, double t_to,
                       double achievable_limit_kN);

}  // namespace bbw::faults::test
