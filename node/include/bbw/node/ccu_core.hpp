// The CCU's per-sample and per-period logic without DDS (docs/distributed.md, docs/faults.md):
// one CornerSupervisor per corner (sample guard, calibrator, fault monitor, reactions), the
// fused clamp-force estimate, and the per-corner commands (the scenario's demand, shared by the
// Redistributor when a corner is unavailable). Pure: time is an argument; per-sample calls do
// not allocate (test_ccu_core_no_alloc), except a corner's rejoin or a gap of unseen samples, which
// rebuild its calibrator.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <optional>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/calibration/config.hpp"
#include "bbw/faults/corner_supervisor.hpp"
#include "bbw/faults/fault_monitor.hpp"
#include "bbw/faults/redistributor.hpp"
#include "bbw/scenario/scenario.hpp"
#include "bbw/node/command_plan.hpp"

namespace bbw::ccu {

inline constexpr std::size_t kSlots = faults::kCorners;  // FL, FR, RL, RR

// What the CCU concluded from one sample (logged per sample).
struct SampleOutcome {
  double estimate_kN = 0.0;   // calibrator: load cell minus friction; else the reaction's estimate
  double friction_kN = 0.0;   // calibrator's friction estimate (NaN when it was not fed)
  double curve_kN = 0.0;      // the trusted curve at the sample's position
  double fused_kN = 0.0;      // the CCU's clamp-force estimate
  bool valid = false;         // an estimate exists
  bool calibrated = false;    // the corner's calibrator has accepted a fit
  bool from_calibrator = false;
};

// The command for one corner and period.
struct CornerPlan {
  CommandMode mode = CommandMode::Profile;
  double clamp_force_kN = 0.0;
  bool available = true;
  std::optional<corner_unit::ForceFeedback> feedback;  // reaction override, if any
  calibration::Curve curve;                            // for feedback == Curve
};

// How the CCU shares the demand when a corner is unavailable. The product always redistributes
// and counts a held force; the switches exist to measure what each reaction is worth (the
// closed-loop tests compare against a CCU without it).
struct ReactionPolicy {
  bool redistribute = true;      // false: keep the nominal split whatever the corners' state
  bool count_held_force = true;  // false: a corner that does not release counts as braking 0
};

class CcuCore {
 public:
  // Throws std::invalid_argument (corner names not FL/FR/RL/RR, twice, bad configs).
  CcuCore(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
          const faults::MonitorParams& monitor = {}, ReactionPolicy policy = {});

  bool has(std::size_t slot) const { return supervisors_[slot] != nullptr; }
  // The scenario index of the corner in `slot`.
  std::size_t scenario_index(std::size_t slot) const { return scenario_index_[slot]; }

  const SampleOutcome& on_sample(std::size_t slot, const faults::CornerReading& r, double arrival_s);
  void on_link_event(std::size_t slot, faults::LinkEvent e, double time_s);
  void tick(double now_s);
  // Commands for the period starting at time_s. With every corner available this is the
  // scenario's nominal split (CommandPlanner); otherwise the Redistributor shares the nominal
  // total among the available corners.
  const std::array<CornerPlan, kSlots>& plan(double time_s);
  // The demanded total clamp force at time_s (sum of the nominal commands), kN.
  double demand_total_kN(double time_s) const;
  // A vehicle run (issue 15): the CCU's brake functions (bbw/brake/) command each corner's clamp
  // force instead of the scenario's pedal profile. A slot with a value is commanded that force
  // in plan() when it is available; nullopt (the default) leaves plan() as it was.
  void set_brake_commands(const std::array<std::optional<double>, kSlots>& clamp_force_kN) { brake_commands_ = clamp_force_kN; }
  // A study of what calibration is worth (issue 15, docs/vehicle.md): every available corner is
  // told to close its loop on `curve` (FEEDBACK_CURVE), e.g. the end-of-line curve, whatever the
  // calibrator learns. nullopt (the default): plan() as it was.
  void set_curve_feedback(const std::optional<calibration::Curve>& curve) { curve_feedback_ = curve; }

  const faults::CornerSupervisor& supervisor(std::size_t slot) const { return *supervisors_[slot]; }

 private:
  const scenario::Scenario& scenario_;
  ReactionPolicy policy_;
  CommandPlanner planner_;
  std::array<std::unique_ptr<faults::CornerSupervisor>, kSlots> supervisors_;
  std::array<std::size_t, kSlots> scenario_index_{};
  std::optional<faults::Redistributor> redistributor_;
  std::array<CornerPlan, kSlots> plans_{};
  std::array<std::optional<double>, kSlots> brake_commands_{};
  std::optional<calibration::Curve> curve_feedback_;
  SampleOutcome outcome_;
};

// The monitor's actuator model from the scenario's plant (torque per ampere, load torque per
// kN, inertia); everything else from `base`.
faults::MonitorParams monitor_params_for(const scenario::Scenario& scenario, faults::MonitorParams base = {});

// One corner's monitor parameters: `monitor_params_for`'s, with what belongs to that corner
// (residual findings on demand-driven corners, its backlash as its end-of-line test measured it).
// The CCU and bbw_monitor_replay both build a corner's monitor from this.
faults::MonitorParams corner_monitor_params(const scenario::Scenario& scenario, std::size_t corner_index,
                                            const faults::MonitorParams& scenario_params);

}  // namespace bbw::ccu
