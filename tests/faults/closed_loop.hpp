// In-memory closed loop for fault tests (no DDS): four CornerSims with their fault injectors
// and CCU watchdogs, and a CCU made of one CornerSupervisor per corner and the Redistributor,
// on one time base. Samples travel in blocks of one CCU period, as over DDS in lockstep; the
// schedule's network faults drop or delay them, a killed corner sends nothing and its motor is
// unpowered, a killed CCU sends no commands.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include "bbw/calibration/config.hpp"
#include "bbw/faults/ccu_watchdog.hpp"
#include "bbw/faults/corner_supervisor.hpp"
#include "bbw/faults/outcome.hpp"
#include "bbw/faults/reading.hpp"
#include "bbw/faults/redistributor.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/scenario/corner_sim.hpp"

namespace bbw::faults::test {

std::string source_path(const std::string& rel);

// What a corner's sample tells the CCU (the force command only when it is a force command);
// seq_offset renumbers a restarted corner's samples.
CornerReading reading_from(const scenario::CornerSample& s, std::uint64_t seq_offset = 0);

struct LoopOptions {
  calibration::CalibratorConfig calibrator;
  MonitorParams monitor;          // actuator model fields are taken from the scenario's plant
  CcuWatchdogParams watchdog;
  double liveliness_lease_s = 0.02;
  bool redistribute = true;          // false: the CCU keeps the nominal split (for comparison)
  bool count_held_force = true;      // false: a corner that does not release counts as braking 0
  // Called for every reading a corner sends; fills `out` with what reaches the CCU (default:
  // the reading itself). Tests add corrupt samples here.
  std::function<void(std::size_t corner, const CornerReading& r, std::vector<CornerReading>& out)> deliver;
};

LoopOptions default_options();

struct PeriodRecord {
  double time_s = 0.0;                    // end of the period
  double demand_total_kN = 0.0;           // demanded total clamp force
  double delivered_total_kN = 0.0;        // sum of true clamp forces
  std::array<double, kCorners> true_kN{};
  std::array<double, kCorners> estimate_kN{};
  std::array<double, kCorners> command_kN{};  // what the CCU asked for (NaN when the CCU is down)
  std::array<double, kCorners> applied_kN{};  // what the corner followed (watchdog output)
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
