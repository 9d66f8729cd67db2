#include "bbw/faults/fault_monitor.hpp"

#include "bbw/faults/bridged_curve.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "bbw/plant/clamp_curve.hpp"

namespace bbw::faults {
namespace {

void require(bool ok, const char* field, double value, const char* rule) {
  if (!ok) throw std::invalid_argument(std::string("MonitorParams.") + field + " = " + std::to_string(value) + ": " + rule);
}
void positive(const char* field, double v) { require(std::isfinite(v) && v > 0.0, field, v, "must be > 0"); }

}  // namespace

void MonitorParams::validate() const {
  guard.validate();
  positive("residual_threshold_kN", residual_threshold_kN);
  require(std::isfinite(uncalibrated_residual_threshold_kN) &&
              uncalibrated_residual_threshold_kN >= residual_threshold_kN,
          "uncalibrated_residual_threshold_kN", uncalibrated_residual_threshold_kN, "must be >= residual_threshold_kN");
  positive("residual_persist_s", residual_persist_s);
  positive("residual_reference_s", residual_reference_s);
  positive("residual_change_threshold_kN", residual_change_threshold_kN);
  positive("residual_sigma_factor", residual_sigma_factor);
  positive("residual_stats_s", residual_stats_s);
  positive("residual_stats_prior_s", residual_stats_prior_s);
  require(std::isfinite(residual_speed_free_rev_per_s) && residual_speed_free_rev_per_s >= 0.0,
          "residual_speed_free_rev_per_s", residual_speed_free_rev_per_s, "must be >= 0");
  require(std::isfinite(residual_speed_kN_per_rev_per_s) && residual_speed_kN_per_rev_per_s >= 0.0,
          "residual_speed_kN_per_rev_per_s", residual_speed_kN_per_rev_per_s, "must be >= 0");
  require(std::isfinite(eol_friction_half_width_kN) && eol_friction_half_width_kN >= 0.0, "eol_friction_half_width_kN",
          eol_friction_half_width_kN, "must be >= 0");
  positive("eol_band_kN", eol_band_kN);
  positive("hold_kN", hold_kN);
  positive("hold_speed_rev_per_s", hold_speed_rev_per_s);
  positive("hold_span_rev", hold_span_rev);
  positive("hold_span_known_rev", hold_span_known_rev);
  require(hold_settle_samples >= 1, "hold_settle_samples", hold_settle_samples, "must be >= 1");
  require(std::isfinite(hold_settled_within_kN) && hold_settled_within_kN >= 0.0, "hold_settled_within_kN",
          hold_settled_within_kN, "must be >= 0");
  positive("revisit_kN", revisit_kN);
  positive("revisit_bin_rev", revisit_bin_rev);
  require(revisit_settle_samples >= 1, "revisit_settle_samples", revisit_settle_samples, "must be >= 1");
  positive("revisit_forget_s", revisit_forget_s);
  positive("modulation_time_constant_s", modulation_time_constant_s);
  positive("modulation_min_spread_rev_per_s", modulation_min_spread_rev_per_s);
  require(std::isfinite(eol_backlash_rev) && eol_backlash_rev >= 0.0, "eol_backlash_rev", eol_backlash_rev, "must be >= 0");
  require(std::isfinite(eol_creep_fraction) && eol_creep_fraction >= 0.0 && eol_creep_fraction < 1.0, "eol_creep_fraction",
          eol_creep_fraction, "must be in [0, 1)");
  positive("eol_creep_time_constant_s", eol_creep_time_constant_s);
  require(std::isfinite(eol_friction_load_gain) && eol_friction_load_gain >= 0.0, "eol_friction_load_gain",
          eol_friction_load_gain, "must be >= 0");
  positive("eol_friction_reference_kN", eol_friction_reference_kN);
  require(std::isfinite(eol_load_cell_kN_per_C), "eol_load_cell_kN_per_C", eol_load_cell_kN_per_C, "must be finite");
  require(std::isfinite(eol_load_cell_delay_s) && eol_load_cell_delay_s >= 0.0 && eol_load_cell_delay_s <= 0.05,
          "eol_load_cell_delay_s", eol_load_cell_delay_s, "must be in [0, 0.05] s");
  require(std::isfinite(eol_viscous_kN_per_rev_per_s) && eol_viscous_kN_per_rev_per_s >= 0.0, "eol_viscous_kN_per_rev_per_s",
          eol_viscous_kN_per_rev_per_s, "must be >= 0");
  require(std::isfinite(eol_load_cell_reference_C), "eol_load_cell_reference_C", eol_load_cell_reference_C, "must be finite");
  require(std::isfinite(eol_friction_model_share) && eol_friction_model_share >= 0.0 && eol_friction_model_share <= 1.0,
          "eol_friction_model_share", eol_friction_model_share, "must be in [0, 1]");
  require(std::isfinite(eol_friction_amplitude_factor) && eol_friction_amplitude_factor >= 1.0,
          "eol_friction_amplitude_factor", eol_friction_amplitude_factor, "must be >= 1");
  require(std::isfinite(eol_relative) && eol_relative >= 0.0, "eol_relative", eol_relative, "must be >= 0");
  require(std::isfinite(eol_speed_kN_per_rev_per_s) && eol_speed_kN_per_rev_per_s >= 0.0, "eol_speed_kN_per_rev_per_s",
          eol_speed_kN_per_rev_per_s, "must be >= 0");
  require(std::isfinite(curve_min_rev), "curve_min_rev", curve_min_rev, "must be finite");
  require(std::isfinite(curve_max_rev) && curve_max_rev > curve_min_rev, "curve_max_rev", curve_max_rev,
          "must be finite and > curve_min_rev");
  positive("jump_threshold_rev", jump_threshold_rev);
  positive("jump_confirm_s", jump_confirm_s);
  positive("jump_window_s", jump_window_s);
  positive("jump_max_gap_s", jump_max_gap_s);
  require(stuck_samples >= 2, "stuck_samples", stuck_samples, "must be >= 2");
  require(stuck_resolver_clear_samples >= 2, "stuck_resolver_clear_samples", stuck_resolver_clear_samples, "must be >= 2");
  positive("stuck_min_travel_rev", stuck_min_travel_rev);
  positive("stuck_min_force_change_kN", stuck_min_force_change_kN);
  require(step_still_samples >= 2 && step_still_samples <= StepDetector::kMaxWindow, "step_still_samples",
          step_still_samples, "must be in [2, 64]");
  positive("step_still_span_rev", step_still_span_rev);
  require(std::isfinite(step_still_max_speed_rev_per_s) && step_still_max_speed_rev_per_s >= 0.0,
          "step_still_max_speed_rev_per_s", step_still_max_speed_rev_per_s, "must be >= 0");
  require(step_min_position_changes >= 1 && step_min_position_changes <= step_still_samples,
          "step_min_position_changes", step_min_position_changes, "must be in [1, step_still_samples]");
  positive("step_kN", step_kN);
  require(step_keep_fraction > 0.0 && step_keep_fraction <= 1.0, "step_keep_fraction", step_keep_fraction,
          "must be in (0, 1]");
  require(step_confirm_samples >= 1, "step_confirm_samples", step_confirm_samples, "must be >= 1");
  require(step_moving_window_samples >= 3 && step_moving_window_samples <= MovingStepDetector::kMaxWindow,
          "step_moving_window_samples", step_moving_window_samples, "must be in [3, 64]");
  positive("step_moving_quiet_fraction", step_moving_quiet_fraction);
  positive("step_moving_unexplained_rev", step_moving_unexplained_rev);
  require(std::isfinite(step_moving_speed_kN_per_rev_per_s) && step_moving_speed_kN_per_rev_per_s >= 0.0,
          "step_moving_speed_kN_per_rev_per_s", step_moving_speed_kN_per_rev_per_s, "must be >= 0");
  positive("unpowered_max_current_A", unpowered_max_current_A);
  require(unpowered_settle_samples >= 2 && unpowered_settle_samples <= UnpoweredHoldDetector::kMaxWindow,
          "unpowered_settle_samples", unpowered_settle_samples, "must be in [2, 64]");
  positive("unpowered_max_speed_rev_per_s", unpowered_max_speed_rev_per_s);
  require(std::isfinite(unpowered_min_load_margin_kN) && unpowered_min_load_margin_kN >= 0.0,
          "unpowered_min_load_margin_kN", unpowered_min_load_margin_kN, "must be >= 0");
  positive("unpowered_kN", unpowered_kN);
  require(stuck_frozen_samples >= 2, "stuck_frozen_samples", stuck_frozen_samples, "must be >= 2");
  require(std::isfinite(stuck_frozen_run_factor) && stuck_frozen_run_factor >= 0.0, "stuck_frozen_run_factor",
          stuck_frozen_run_factor, "must be finite and >= 0");
  require(frozen_attribution_samples >= 2, "frozen_attribution_samples", frozen_attribution_samples, "must be >= 2");
  require(noise_window_samples >= 4 && noise_window_samples <= kMaxNoiseWindow, "noise_window_samples",
          noise_window_samples, "must be in [4, 256]");
  positive("noise_step_kN", noise_step_kN);
  positive("noise_second_difference_kN", noise_second_difference_kN);
  require(std::isfinite(noise_learned_factor) && noise_learned_factor >= 0.0, "noise_learned_factor",
          noise_learned_factor, "must be finite and >= 0");
  positive("noise_learn_time_constant_s", noise_learn_time_constant_s);
  positive("noise_second_difference_learn_s", noise_second_difference_learn_s);
  require(noise_min_fraction > 0.0 && noise_min_fraction <= 1.0, "noise_min_fraction", noise_min_fraction,
          "must be in (0, 1]");
  require(dropout_samples >= 1, "dropout_samples", dropout_samples, "must be >= 1");
  require(dropout_clear_samples >= 1, "dropout_clear_samples", dropout_clear_samples, "must be >= 1");
  positive("torque_per_A_Nm", torque_per_A_Nm);
  positive("Nm_per_kN", Nm_per_kN);
  require(torque_fraction_threshold > 0.0 && torque_fraction_threshold < 1.0, "torque_fraction_threshold",
          torque_fraction_threshold, "must be in (0, 1)");
  positive("inertia_kg_m2", inertia_kg_m2);
  positive("torque_filter_s", torque_filter_s);
  positive("torque_check_min_torque_Nm", torque_check_min_torque_Nm);
  require(torque_lost_threshold > 0.0 && torque_lost_threshold < torque_fraction_threshold, "torque_lost_threshold",
          torque_lost_threshold, "must be in (0, torque_fraction_threshold)");
  require(torque_lost_braking_threshold > 0.0 && torque_lost_braking_threshold <= torque_lost_threshold,
          "torque_lost_braking_threshold", torque_lost_braking_threshold, "must be in (0, torque_lost_threshold]");
  require(torque_check_moving_low_load_kN >= 0.0 && torque_check_moving_low_load_kN <= torque_check_moving_min_load_kN,
          "torque_check_moving_low_load_kN", torque_check_moving_low_load_kN, "must be in [0, torque_check_moving_min_load_kN]");
  require(torque_loss_braking_threshold == 0.0 ||
              (torque_loss_braking_threshold > torque_lost_braking_threshold && torque_loss_braking_threshold <= 1.0),
          "torque_loss_braking_threshold", torque_loss_braking_threshold,
          "must be 0 (off) or in (torque_lost_braking_threshold, 1]");
  positive("torque_lost_persist_s", torque_lost_persist_s);
  require(std::isfinite(drive.coulomb_friction_Nm) && drive.coulomb_friction_Nm >= 0.0, "drive.coulomb_friction_Nm",
          drive.coulomb_friction_Nm, "must be >= 0");
  positive("drive.coulomb_smoothing_rev_per_s", drive.coulomb_smoothing_rev_per_s);
  require(std::isfinite(drive.viscous_friction_Nm_per_rev_per_s) && drive.viscous_friction_Nm_per_rev_per_s >= 0.0,
          "drive.viscous_friction_Nm_per_rev_per_s", drive.viscous_friction_Nm_per_rev_per_s, "must be >= 0");
  positive("unexplained_margin_Nm", unexplained_margin_Nm);
  require(std::isfinite(unexplained_relative) && unexplained_relative >= 0.0, "unexplained_relative",
          unexplained_relative, "must be >= 0");
  positive("unexplained_max_speed_rev_per_s", unexplained_max_speed_rev_per_s);
  positive("unexplained_persist_s", unexplained_persist_s);
  positive("seized_static_rev", seized_static_rev);
  positive("seized_window_s", seized_window_s);
  positive("seized_ramp_Nm", seized_ramp_Nm);
  positive("seized_force_error_kN", seized_force_error_kN);
  require(seized_ramp_off_command_Nm == 0.0 || seized_ramp_off_command_Nm >= seized_ramp_Nm, "seized_ramp_off_command_Nm",
          seized_ramp_off_command_Nm, "must be 0 (off) or >= seized_ramp_Nm");
  require(std::isfinite(test_pulse_current_A) && test_pulse_current_A >= 0.0, "test_pulse_current_A",
          test_pulse_current_A, "must be >= 0");
  require(test_pulse_s >= 0.0005 && test_pulse_s <= 0.007, "test_pulse_s", test_pulse_s, "must be in [0.0005, 0.007]");
  positive("test_pulse_max_speed_rev_per_s", test_pulse_max_speed_rev_per_s);
  require(test_pulse_answer_ratio > 0.0 && test_pulse_answer_ratio < 1.0, "test_pulse_answer_ratio",
          test_pulse_answer_ratio, "must be in (0, 1)");
  require(test_pulse_unanswered >= 1, "test_pulse_unanswered", test_pulse_unanswered, "must be >= 1");
  positive("test_pulse_within_s", test_pulse_within_s);
  require(test_pulse_lost_mean_ratio > 0.0 && test_pulse_lost_mean_ratio <= test_pulse_answer_ratio,
          "test_pulse_lost_mean_ratio", test_pulse_lost_mean_ratio, "must be in (0, test_pulse_answer_ratio]");
  require(test_pulse_weak_count >= 0 && test_pulse_weak_count <= TorqueDetector::kMaxWeakCount, "test_pulse_weak_count",
          test_pulse_weak_count, "must be in [0, TorqueDetector::kMaxWeakCount (32)]");
  static_assert(TorqueDetector::kMaxWeakCount == 32, "the rule's text above names it");
  require(test_pulse_weak_fraction > 0.0 && test_pulse_weak_fraction < 1.0, "test_pulse_weak_fraction",
          test_pulse_weak_fraction, "must be in (0, 1)");
  require(test_pulse_healthy_ratio > 0.0 && test_pulse_healthy_ratio <= 2.0, "test_pulse_healthy_ratio",
          test_pulse_healthy_ratio, "must be in (0, 2]");
  require(test_pulse_learn_count >= 1, "test_pulse_learn_count", test_pulse_learn_count, "must be >= 1");
  positive("torque_check_min_load_kN", torque_check_min_load_kN);
  positive("torque_check_max_speed_rev_per_s", torque_check_max_speed_rev_per_s);
  require(std::isfinite(torque_check_moving_min_speed_rev_per_s) && torque_check_moving_min_speed_rev_per_s >= 0.0,
          "torque_check_moving_min_speed_rev_per_s", torque_check_moving_min_speed_rev_per_s, "must be >= 0");
  positive("torque_check_moving_min_load_kN", torque_check_moving_min_load_kN);
  positive("torque_persist_s", torque_persist_s);
  positive("tracking_time_constant_s", tracking_time_constant_s);
  positive("tracking_threshold_kN", tracking_threshold_kN);
  require(tracking_relative >= 0.0 && tracking_relative < 1.0, "tracking_relative", tracking_relative,
          "must be in [0, 1)");
  positive("tracking_persist_s", tracking_persist_s);
  require(tracking_full_speed_fraction >= 0.0 && tracking_full_speed_fraction <= 1.0, "tracking_full_speed_fraction",
          tracking_full_speed_fraction, "must be in [0, 1]");
  require(std::isfinite(drive_max_speed_rev_per_s) && drive_max_speed_rev_per_s >= 0.0, "drive_max_speed_rev_per_s",
          drive_max_speed_rev_per_s, "must be >= 0");
  positive("force_limit_kN", force_limit_kN);
  positive("release_min_speed_rev_per_s", release_min_speed_rev_per_s);
  positive("deadline_s", deadline_s);
}

const char* to_string(Finding f) {
  switch (f) {
    case Finding::None: return "none";
    case Finding::LoadCellOffset: return "load_cell_offset";
    case Finding::LoadCellStuck: return "load_cell_stuck";
    case Finding::LoadCellNoisy: return "load_cell_noisy";
    case Finding::LoadCellMissing: return "load_cell_missing";
    case Finding::ResolverOffset: return "resolver_offset";
    case Finding::ResolverStuck: return "resolver_stuck";
    case Finding::ActuatorTorqueLoss: return "actuator_torque_loss";
    case Finding::ActuatorLost: return "actuator_lost";
    case Finding::ActuatorTracking: return "actuator_tracking";
    case Finding::ActuatorNotReleasing: return "actuator_not_releasing";
    case Finding::LinkLost: return "link_lost";
    case Finding::ProcessLost: return "process_lost";
  }
  return "?";
}

Part part_of(Finding f) {
  switch (f) {
    case Finding::ResolverOffset:
    case Finding::ResolverStuck: return Part::Resolver;
    case Finding::ActuatorTorqueLoss:
    case Finding::ActuatorLost:
    case Finding::ActuatorTracking:
    case Finding::ActuatorNotReleasing: return Part::Actuator;
    case Finding::LinkLost: return Part::Network;
    case Finding::ProcessLost: return Part::Process;
    default: return Part::LoadCell;
  }
}

namespace {

// The corner's parameters as its monitor uses them. The residual rules' speed allowances
// (residual.speed_kN_per_rev_per_s, end_of_line.speed_kN_per_rev_per_s: 0.3 = viscous friction
// 0.2 + a load cell's 5 ms delay 0.1) are for speed effects no model carries: with
// eol_viscous_narrows_speed_allowance, a viscous term the end-of-line model puts in the expected
// reading is taken out of them (tune run 22, tune_b run 554: a positive drift in a fast apply,
// named only because the viscous term added to it, was missed once the model took the term out
// and the allowance still held it).
MonitorParams for_corner(const MonitorParams& params) {
  params.validate();
  MonitorParams p = params;
  // The viscous coefficient the residual rules use: 0 without the model or an end-of-line curve.
  if (!p.eol_viscous_model || !p.eol_curve) p.eol_viscous_kN_per_rev_per_s = 0.0;
  if (p.eol_viscous_narrows_speed_allowance) {
    p.residual_speed_kN_per_rev_per_s = std::max(0.0, p.residual_speed_kN_per_rev_per_s - p.eol_viscous_kN_per_rev_per_s);
    p.eol_speed_kN_per_rev_per_s = std::max(0.0, p.eol_speed_kN_per_rev_per_s - p.eol_viscous_kN_per_rev_per_s);
  }
  return p;
}

}  // namespace

GuardLimits guard_for_corner(const MonitorParams& p) {
  GuardLimits g = p.guard;
  if (!p.guard_position_from_eol || !p.eol_curve) return g;
  const plant::ClampCurve curve(*p.eol_curve);
  const double t_C = p.eol_curve->reference_temperature_C;
  if (curve.force_kN(g.position_max_rev, t_C, 0.0) >= g.load_cell_max_kN) return g;
  // (At most 1000 rev, a curve that never reaches the range.)
  g.position_max_rev = eol_position_at(curve, g.load_cell_max_kN, t_C, g.position_max_rev, 1000.0);
  return g;
}

FaultMonitor::FaultMonitor(const MonitorParams& params, Target corner)
    : p_(for_corner(params)), corner_(corner), residual_(p_), torque_(p_), step_(p_), moving_step_(p_) {
  if (!corner_slot(corner)) throw std::invalid_argument("FaultMonitor: monitors a corner, not the CCU");
}

void FaultMonitor::set_curve_range(double min_rev, double max_rev) {
  residual_.set_curve_range(std::max(min_rev, p_.curve_min_rev), std::min(max_rev, p_.curve_max_rev));
}

void FaultMonitor::update(const CornerReading& r, const SampleCheck& check, const calibration::Estimate* estimate,
                          double force_estimate_kN, double arrival_s, double load_cell_friction_kN) {
  // Any arrival, even a corrupt one, shows that the corner is there; the end of an outage that
  // lost samples breaks every detector's continuity. A delay loses none: when the first sample
  // after the outage continues the corner's sequence, every detector keeps its state (resetting
  // the end-of-line friction model made a reversal 1 ms after a delayed corner rejoined look like
  // a noisy load cell: tuning seed 1401 run 289).
  const bool continues = have_prev_ && r.seq == prev_.seq + 1;
  if (link_.on_arrival(arrival_s, arbiter_) && !continues) {
    have_prev_ = false;
    noise_.on_rejoin();
    tracking_.on_rejoin();
    residual_.on_rejoin();
    torque_.on_rejoin();
    stuck_.on_rejoin();
    step_.on_rejoin();
    moving_step_.on_rejoin();
    unpowered_.on_rejoin();
    dropout_.on_rejoin();
  }
  if (!check.usable()) return;  // corrupt: counted by the guard, never used
  // Usable again after samples the guard rejected (or that never came, within one incarnation):
  // where the position went meanwhile is unknown, so is the keys' state (MonitorParams::
  // residual_unseen_gap_forgets).
  if (unseen_gap_before(r)) residual_.on_rejoin();

  const SampleContext c{r, check, have_prev_, prev_, prev_lc_present_, have_prev_ ? r.time_s - prev_.time_s : 0.0};
  dropout_.update(c, p_, arbiter_);
  jump_.update(c, p_, arbiter_);
  stuck_.update(c, p_, arbiter_);
  step_.update(c, p_, arbiter_);
  moving_step_.update(c, p_, arbiter_);
  unpowered_.update(c, commutation_lost(), p_, arbiter_);
  // A resolver named offset (and not stuck: the finding is its first) still measures the motion:
  // less the offsets its confirmed jumps measured, the position the residual rules need.
  // Only while every step since the start was seen: an offset that began in a gap (a silent
  // link) and ended in sight left a sum of the wrong sign (CI subset run 32, a faulty run's
  // unexplained load_cell_offset).
  const bool compensated = p_.jump_compensate && jump_.offset_tracked() && !arbiter_.ok(Part::Resolver) &&
                           arbiter_.diagnosis(Part::Resolver).finding == Finding::ResolverOffset && p_.eol_curve;
  if (jump_.began()) residual_.save_position();  // before this sample's step
  CornerReading corrected = r;
  if (compensated) corrected.position_rev -= jump_.offset_rev();
  if (arbiter_.ok(Part::Resolver)) {
    residual_.track_position(r, p_);
  } else if (compensated) {
    // Each confirmed jump changes the offset; the samples between a jump and its confirmation
    // had the wrong position: the position's state goes back to before the jump, the rules'
    // references start again.
    if (jump_.confirmed() != compensated_jumps_) {
      compensated_jumps_ = jump_.confirmed();
      residual_.restore_position();
      residual_.restart_rules();
    }
    residual_.track_position(corrected, p_);
  } else {
    residual_.forget_position();
  }
  // The most clamp force the position allows, while the resolver is judged right.
  double clamp_upper_kN = std::numeric_limits<double>::quiet_NaN();
  double clamp_lower_kN = std::numeric_limits<double>::quiet_NaN();
  if (estimate != nullptr && estimate->valid) {
    residual_.update(r, *estimate, p_, arbiter_, noise_, stuck_, jump_);
    if (arbiter_.ok(Part::Resolver)) {
      clamp_upper_kN = residual_.clamp_upper_kN();
      clamp_lower_kN = residual_.clamp_lower_kN();
    }
  } else if (compensated && arbiter_.ok(Part::LoadCell) && check.load_cell_present && std::isfinite(r.force_kN)) {
    // No calibrator here (it is fed only with both sensors right): the end-of-line curve and band.
    calibration::Estimate eol_only;
    eol_only.valid = true;
    eol_only.force_kN = r.force_kN;
    eol_only.curve_force_kN = r.force_kN;
    residual_.update(corrected, eol_only, p_, arbiter_, noise_, stuck_, jump_);
  } else if (!arbiter_.ok(Part::Resolver) && arbiter_.ok(Part::LoadCell) && have_prev_ && check.load_cell_present &&
             prev_lc_present_ && std::isfinite(r.force_kN) && std::isfinite(prev_.force_kN)) {
    // No residual without the position: a noisy load cell is still found by its own differences.
    noise_.update_load_cell_difference(r.force_kN - prev_.force_kN, r.time_s, p_, arbiter_);
  }
  const bool load_cell_load = check.load_cell_present && arbiter_.ok(Part::LoadCell);
  const double load_kN = load_cell_load ? r.force_kN : force_estimate_kN;
  // The torque rules judge the position the residual rules do (less a named offset's).
  const SampleContext tc{compensated ? corrected : r, check, have_prev_, prev_, prev_lc_present_, c.dt_s};
  torque_.update(tc, load_kN, load_cell_load, compensated || arbiter_.ok(Part::Resolver), p_, arbiter_);
  if (torque_.test_pulse_samples() > 0) step_.on_test_pulse(torque_.test_pulse_samples(), r.time_s, p_);
  // Without commutation the force no longer follows the command because of the resolver, not of
  // a second fault in the actuator.
  if (commutation_lost()) {
    tracking_.on_rejoin();
  } else {
    const bool counts = estimate != nullptr && (p_.tracking_friction_as_subtracted ||
                                                (p_.tracking_friction_after_restart ? estimate->friction_fitted : estimate->calibrated));
    const bool lc_trusted = check.load_cell_present && arbiter_.ok(Part::LoadCell);
    double friction_kN = counts && estimate->valid && lc_trusted ? estimate->friction_kN : 0.0;
    if (estimate == nullptr && lc_trusted && p_.lost_resolver_tracking_counts_friction && std::isfinite(load_cell_friction_kN)) {
      friction_kN = load_cell_friction_kN;
    }
    tracking_.update(c, force_estimate_kN, friction_kN, clamp_upper_kN, clamp_lower_kN, p_, arbiter_);
  }

  prev_ = r;
  prev_lc_present_ = check.load_cell_present;
  have_prev_ = true;
}

}  // namespace bbw::faults
