// One corner as the CCU sees it (docs/faults.md): the sample guard, the calibrator, the fault
// monitor and the reactions, in the order the CCU process calls them. Pure; per-sample calls do
// not allocate (a rejoin after a lost process rebuilds the calibrator, which does).
//
//   CornerSupervisor sup(calibrator_config, monitor_params, Target::FL);
//   per received sample:   const CornerView& v = sup.on_sample(reading, arrival_s);
//   per CCU period:        sup.tick(now_s);          // deadline check
//   DDS listener events:   sup.on_link_event(LinkEvent::LivelinessLost, now_s);
//   command to the corner: v.available, v.force_limit_kN (Redistributor), v.feedback, v.curve
#pragma once

#include <cstdint>
#include <limits>
#include <optional>


#include "bbw/calibration/calibrator.hpp"
#include "bbw/calibration/fusion.hpp"
#include "bbw/calibration/config.hpp"
#include "bbw/model/delay_line.hpp"
#include "bbw/plant/clamp_curve.hpp"
#include "bbw/corner_unit/controller.hpp"
#include "bbw/faults/fault_monitor.hpp"
#include "bbw/faults/bridged_curve.hpp"
#include "bbw/faults/last_good.hpp"
#include "bbw/faults/sample_guard.hpp"

namespace bbw::faults {

enum class EstimateSource : std::uint8_t {
  None,             // no trusted estimate (no usable sample yet, or both sensors faulty)
  Calibrator,       // load cell minus the calibrator's friction estimate
  Curve,            // the last good curve at the measured position (load cell faulty or missing)
  LoadCell,         // load cell minus the friction frozen at the resolver fault (resolver faulty)
};
const char* to_string(EstimateSource s);

struct CornerView {
  double force_estimate_kN = std::numeric_limits<double>::quiet_NaN();
  EstimateSource source = EstimateSource::None;
  bool available = false;        // may be given a share of the braking demand
  double force_limit_kN = 0.0;   // for the Redistributor
  // A corner whose actuator does not release (ActuatorNotReleasing) still brakes with this
  // force (its current estimate); 0 otherwise. The Redistributor counts it on its axle.
  double held_kN = 0.0;
  // Force feedback the corner should use instead of its own choice (a reaction), if any.
  std::optional<corner_unit::ForceFeedback> feedback;
  calibration::Curve curve;      // the curve the CCU trusts for this corner
  bool estimate_valid() const { return source != EstimateSource::None; }
};

// The calibrator config a corner's calibrator starts from: `c` with what the caliper's end-of-line
// test in `m` measured, each item under its own MonitorParams::calibrator_* switch: its curve as
// the initial curve (a cubic over the range at the curve's reference temperature), its viscous,
// load-friction and backlash terms, its range (only narrower) and largest element, and its keys as
// initial_friction (the fits' prior). Offline calibration that should match a CCU's starts from
// the same (SystemLockstep.CcuEstimatesEqualOfflineCalibration; calibration::to_yaml writes it).
calibration::CalibratorConfig calibrator_start(calibration::CalibratorConfig c, const MonitorParams& m);

class CornerSupervisor {
 public:
  // Throws std::invalid_argument for invalid configs or Target::CCU.
  CornerSupervisor(const calibration::CalibratorConfig& calibrator, const MonitorParams& monitor, Target corner);

  const CornerView& on_sample(const CornerReading& r, double arrival_s);
  void on_link_event(LinkEvent e, double time_s);
  const CornerView& tick(double now_s);

  const CornerView& view() const { return view_; }
  // The calibrator's output for the last sample given to on_sample (valid == false when the
  // calibrator was not fed it: corrupt sample, missing load cell, faulty sensor, rejoin).
  const calibration::Estimate& last_estimate() const { return last_estimate_; }
  const calibration::Calibrator& calibrator() const { return *calibrator_; }
  const FaultMonitor& monitor() const { return monitor_; }
  const SampleGuard& guard() const { return guard_; }
  const LastGoodCalibration& last_good() const { return last_good_; }
  std::uint64_t calibrator_restarts() const { return restarts_; }
  std::uint64_t samples_fed() const { return fed_; }
  Target corner() const { return corner_; }

 private:
  // The guard's limits are computed once (guard_for_corner) and given to both the guard and the
  // calibrator's accept range.
  CornerSupervisor(const calibration::CalibratorConfig& calibrator, const MonitorParams& monitor, Target corner,
                   const GuardLimits& guard);
  void resume_after_dropout();
  void resume_after_resolver();
  void restart_calibrator();
  void react_to_new_findings();
  void rejoin();
  void refresh_view(const CornerReading* r, const SampleCheck* c, const calibration::Estimate* e);

  calibration::CalibratorConfig config_;
  Target corner_;
  SampleGuard guard_;
  std::optional<calibration::Calibrator> calibrator_;
  // f_hat fused with the curve by the curve's learned error (calibration/fusion.hpp).
  calibration::EstimateFusion fusion_{calibration::FusionParams{}};
  double fused_kN_ = 0.0;
  double last_fed_time_s_ = std::numeric_limits<double>::quiet_NaN();
  FaultMonitor monitor_;
  LastGoodCalibration last_good_;
  CornerView view_;
  calibration::Estimate last_estimate_;
  bool load_cell_reacted_ = false;
  bool resolver_reacted_ = false;
  calibration::Curve trusted_curve_;
  // The calibrator's key friction over the last kFrictionHistory samples fed while the resolver
  // was judged right: a resolver finding freezes the newest (or, with MonitorParams::
  // lost_resolver_friction_before_onset, the newest before the fault's onset).
  static constexpr std::size_t kFrictionHistory = 256;
  model::DelayLine friction_history_{kFrictionHistory};
  // After a resolver fault: the key friction followed from the load cell's own motion (a play in
  // force: it absorbs a change of the load up to its width, then the clamp force moves).
  double load_friction_kN_ = 0.0;
  double load_filtered_kN_ = std::numeric_limits<double>::quiet_NaN();
  std::optional<plant::ClampCurve> eol_;  // the corner's end-of-line curve, when the scenario has one
  double fed_min_rev_ = std::numeric_limits<double>::infinity();   // positions the calibrator saw
  double fed_max_rev_ = -std::numeric_limits<double>::infinity();
  double last_temperature_C_ = std::numeric_limits<double>::quiet_NaN();  // the last usable sample's
  std::uint64_t restarts_ = 0;
  std::uint64_t fed_ = 0;
};

}  // namespace bbw::faults
