#include "bbw/faults/monitor_yaml.hpp"

#include <stdexcept>

namespace bbw::faults {

using bbw::config::Range;
using bbw::config::Reader;

MonitorParams read_monitor_params(Reader& r) {
  MonitorParams p;
  const Range pos = Range::positive();
  auto g = r.map("guard");
  p.guard.position_min_rev = g.number("position_min_rev");
  p.guard.position_max_rev = g.number("position_max_rev");
  p.guard.speed_abs_max_rev_per_s = g.number("speed_abs_max_rev_per_s", pos);
  p.guard.load_cell_min_kN = g.number("load_cell_min_kN");
  p.guard.load_cell_max_kN = g.number("load_cell_max_kN");
  p.guard.current_abs_max_A = g.number("current_abs_max_A", pos);
  p.guard.max_sequence_jump = g.number("max_sequence_jump", Range::at_least(1.0));
  p.guard.max_time_jump_s = g.number("max_time_jump_s", pos);
  p.guard_position_from_eol = g.boolean("position_from_end_of_line");
  p.guard_diagnosed_load_cell_absent = g.boolean("diagnosed_load_cell_out_of_range_is_absent");
  g.finish();

  auto res = r.map("residual");
  p.residual_threshold_kN = res.number("threshold_kN", pos);
  p.uncalibrated_residual_threshold_kN = res.number("uncalibrated_threshold_kN", pos);
  p.residual_persist_s = res.number("persist_s", pos);
  p.residual_reference_s = res.number("reference_s", pos);
  p.residual_change_threshold_kN = res.number("change_threshold_kN", pos);
  p.residual_sigma_factor = res.number("sigma_factor", pos);
  p.residual_stats_s = res.number("stats_s", pos);
  p.residual_stats_prior_s = res.number("stats_prior_s", pos);
  p.residual_stats_clip = res.number("stats_clip", config::Range::non_negative());
  p.residual_speed_kN_per_rev_per_s = res.number("speed_kN_per_rev_per_s", config::Range::non_negative());
  p.residual_speed_free_rev_per_s = res.number("speed_free_rev_per_s", config::Range::non_negative());
  {
    auto eol = res.map("end_of_line");
    p.eol_band_kN = eol.number("band_kN", pos);
    p.eol_relative = eol.number("relative", config::Range::non_negative());
    p.eol_speed_kN_per_rev_per_s = eol.number("speed_kN_per_rev_per_s", config::Range::non_negative());
    p.eol_friction_amplitude_factor = eol.number("friction_amplitude_factor", config::Range::at_least(1.0));
    p.eol_friction_model_share = eol.number("friction_model_share", config::Range::closed(0.0, 1.0));
    p.eol_creep_model = eol.boolean("creep_model");
    p.eol_friction_load_model = eol.boolean("friction_load_model");
    p.eol_thermal_offset_model = eol.boolean("thermal_offset_model");
    p.eol_viscous_model = eol.boolean("viscous_model");
    p.eol_viscous_narrows_speed_allowance = eol.boolean("viscous_narrows_speed_allowance");
    p.eol_delay_model = eol.boolean("delay_model");
    p.calibrated_two_friction_models = eol.boolean("calibrated_two_friction_models");
    p.calibrated_capped_by_eol = eol.boolean("calibrated_capped");
    p.eol_play_allowance = eol.boolean("play_allowance");
    eol.finish();
  }
  {
    auto h = res.map("hold");
    p.hold_kN = h.number("kN", pos);
    p.hold_speed_rev_per_s = h.number("speed_rev_per_s", pos);
    p.hold_span_rev = h.number("span_rev", pos);
    p.hold_span_known_rev = h.number("span_known_rev", pos);
    p.hold_settle_samples = static_cast<int>(h.integer("settle_samples", 1, 100000));
    p.hold_settled_within_kN = h.number("settled_within_kN", config::Range::non_negative());
    p.hold_calibrated = h.boolean("calibrated");
    p.hold_rebase = h.boolean("rebase");
    p.hold_friction_as_moved = h.boolean("friction_as_moved");
    p.hold_friction_swing = h.boolean("friction_swing");
    p.hold_restart_untrusted = h.boolean("restart_untrusted");
    p.hold_play_allowance = h.boolean("play_allowance");
    p.hold_play_allowance_over_span = h.boolean("play_allowance_over_span");
    h.finish();
  }
  {
    auto v = res.map("revisit");
    p.revisit = v.boolean("enabled");
    p.revisit_kN = v.number("kN", pos);
    p.revisit_bin_rev = v.number("bin_rev", pos);
    p.revisit_settle_samples = static_cast<int>(v.integer("settle_samples", 1, 100000));
    p.revisit_forget_s = v.number("forget_s", pos);
    v.finish();
  }
  {
    auto m = res.map("modulation");
    p.modulation = m.boolean("enabled");
    p.modulation_time_constant_s = m.number("time_constant_s", pos);
    p.modulation_min_spread_rev_per_s = m.number("min_spread_rev_per_s", pos);
    m.finish();
  }
  p.residual_low_upper_bound = res.boolean("low_upper_bound");
  p.residual_low_lower_bound = res.boolean("low_lower_bound");
  p.residual_low_static_span_rev = res.number("low_static_span_rev", config::Range::non_negative());
  p.curve_min_rev = res.number("curve_min_rev");
  p.curve_max_rev = res.number("curve_max_rev");
  p.residual_unseen_gap_forgets = res.boolean("unseen_gap_forgets");
  p.residual_on_profile_corners = res.boolean("on_profile_corners");
  res.finish();

  auto j = r.map("resolver_jump");
  p.jump_threshold_rev = j.number("threshold_rev", pos);
  p.jump_confirm_s = j.number("confirm_s", pos);
  p.jump_window_s = j.number("window_s", pos);
  p.jump_max_gap_s = j.number("max_gap_s", pos);
  p.jump_compensate = j.boolean("compensate");
  j.finish();

  auto s = r.map("stuck");
  p.stuck_samples = static_cast<int>(s.integer("samples", 2, 100000));
  p.stuck_min_travel_rev = s.number("min_travel_rev", pos);
  p.stuck_min_force_change_kN = s.number("min_force_change_kN", pos);
  p.frozen_attribution_samples = static_cast<int>(s.integer("frozen_attribution_samples", 2, 100000));
  p.stuck_frozen_samples = static_cast<int>(s.integer("frozen_samples", 2, 100000));
  p.stuck_frozen_run_factor = s.number("frozen_run_factor", config::Range::closed(0.0, 1000.0));
  p.stuck_resolver_clear_samples = static_cast<int>(s.integer("resolver_clear_samples", 2, 100000));
  s.finish();

  auto st = r.map("step");
  p.step_still_samples = static_cast<int>(st.integer("still_samples", 2, StepDetector::kMaxWindow));
  p.step_still_span_rev = st.number("still_span_rev", pos);
  p.step_still_max_speed_rev_per_s = st.number("still_max_speed_rev_per_s", config::Range::non_negative());
  p.step_min_position_changes = static_cast<int>(st.integer("min_position_changes", 1, StepDetector::kMaxWindow));
  p.step_kN = st.number("step_kN", pos);
  p.step_keep_fraction = st.number("keep_fraction", Range{0.0, 1.0, true, false});
  p.step_confirm_samples = static_cast<int>(st.integer("confirm_samples", 1, 1000));
  p.step_friction_allowance = st.boolean("friction_allowance");
  {
    auto mv = st.map("moving");
    p.step_moving = mv.boolean("enabled");
    p.step_moving_window_samples = static_cast<int>(mv.integer("window_samples", 3, MovingStepDetector::kMaxWindow));
    p.step_moving_quiet_fraction = mv.number("quiet_fraction", pos);
    p.step_moving_unexplained_rev = mv.number("unexplained_position_rev", pos);
    p.step_moving_speed_kN_per_rev_per_s = mv.number("speed_kN_per_rev_per_s", config::Range::non_negative());
    p.step_moving_resolver_stuck_pads_off = mv.boolean("resolver_stuck_pads_off");
    mv.finish();
  }
  st.finish();

  auto up = r.map("unpowered");
  p.unpowered_hold = up.boolean("enabled");
  p.unpowered_max_current_A = up.number("max_current_A", pos);
  p.unpowered_settle_samples = static_cast<int>(up.integer("settle_samples", 2, UnpoweredHoldDetector::kMaxWindow));
  p.unpowered_max_speed_rev_per_s = up.number("max_speed_rev_per_s", pos);
  p.unpowered_coast_bound = up.boolean("coast_bound");
  p.unpowered_min_load_margin_kN = up.number("min_load_margin_kN", config::Range::non_negative());
  p.unpowered_kN = up.number("kN", pos);
  up.finish();

  auto n = r.map("noise");
  p.noise_window_samples = static_cast<int>(n.integer("window_samples", 4, kMaxNoiseWindow));
  p.noise_step_kN = n.number("step_kN", pos);
  p.noise_min_fraction = n.number("min_fraction", Range{0.0, 1.0, true, false});
  p.noise_second_difference_kN = n.number("second_difference_kN", pos);
  p.noise_learned_factor = n.number("learned_factor", Range{0.0, 100.0, true, true});
  p.noise_learn_time_constant_s = n.number("learn_time_constant_s", pos);
  p.noise_second_difference_learn_s = n.number("second_difference_learn_s", pos);
  p.noise_released = n.boolean("released");
  p.noise_paths_restart_learning = n.boolean("paths_restart_learning");
  n.finish();

  auto d = r.map("dropout");
  p.dropout_samples = static_cast<int>(d.integer("samples", 1, 100000));
  p.dropout_clear_samples = static_cast<int>(d.integer("clear_samples", 1, 100000));
  d.finish();

  auto lost = r.map("load_cell_lost");
  p.lost_load_cell_curve_from_eol = lost.boolean("curve_from_end_of_line_beyond_data");
  lost.finish();

  auto start = r.map("calibrator_start");
  p.calibrator_initial_curve_from_eol = start.boolean("initial_curve_from_end_of_line");
  p.calibrator_viscous_from_eol = start.boolean("viscous_term_from_end_of_line");
  p.calibrator_load_friction_from_eol = start.boolean("load_friction_from_end_of_line");
  p.calibrator_backlash_from_eol = start.boolean("backlash_from_end_of_line");
  p.calibrator_range_from_eol = start.boolean("range_from_end_of_line");
  p.calibrator_elements_from_eol = start.boolean("elements_from_end_of_line");
  p.calibrator_friction_from_eol = start.boolean("friction_from_end_of_line");
  p.calibrator_friction_prior_weight = start.number("friction_prior_weight", Range::non_negative());
  start.finish();

  auto lost_resolver = r.map("resolver_lost");
  p.lost_resolver_friction_before_onset = lost_resolver.boolean("friction_from_before_onset");
  p.lost_resolver_tracking_counts_friction = lost_resolver.boolean("tracking_counts_friction");
  lost_resolver.finish();

  auto t = r.map("torque");
  p.torque_filter_s = t.number("filter_s", pos);
  p.torque_check_min_load_kN = t.number("check_min_load_kN", pos);
  p.torque_check_min_torque_Nm = t.number("check_min_torque_Nm", pos);
  p.torque_fraction_threshold = t.number("fraction_threshold", Range{0.0, 1.0, true, true});
  p.torque_check_max_speed_rev_per_s = t.number("check_max_speed_rev_per_s", pos);
  p.torque_check_moving_min_speed_rev_per_s = t.number("check_moving_min_speed_rev_per_s", Range::non_negative());
  p.torque_check_moving_min_load_kN = t.number("check_moving_min_load_kN", pos);
  p.torque_check_moving_low_load_kN = t.number("check_moving_low_load_kN", Range::non_negative());
  p.test_pulse_max_speed_rev_per_s = t.number("test_pulse_max_speed_rev_per_s", pos);
  p.test_pulse_answer_ratio = t.number("test_pulse_answer_ratio", Range{0.0, 1.0, true, true});
  p.test_pulse_unanswered = static_cast<int>(t.integer("test_pulse_unanswered", 1, 1000));
  p.test_pulse_within_s = t.number("test_pulse_within_s", pos);
  p.test_pulse_lost_mean_ratio = t.number("test_pulse_lost_mean_ratio", Range{0.0, 1.0, true, true});
  p.test_pulse_crossing_extremes = t.boolean("test_pulse_crossing_extremes");
  p.test_pulse_rescaled_after_loss = t.boolean("test_pulse_rescaled_after_loss");
  p.test_pulse_weak_count = static_cast<int>(t.integer("test_pulse_weak_count", 0, TorqueDetector::kMaxWeakCount));
  p.test_pulse_weak_fraction = t.number("test_pulse_weak_fraction", Range{0.0, 1.0, true, true});
  p.test_pulse_healthy_ratio = t.number("test_pulse_healthy_ratio", Range{0.0, 2.0, true, false});
  p.test_pulse_learn_count = static_cast<int>(t.integer("test_pulse_learn_count", 1, 1000000));
  p.torque_persist_s = t.number("persist_s", pos);
  p.torque_lost_threshold = t.number("lost_threshold", Range{0.0, 1.0, true, true});
  p.torque_lost_persist_s = t.number("lost_persist_s", pos);
  p.torque_loss_rescales_drive = t.boolean("loss_rescales_drive");
  p.torque_lost_unmeasured_load_high = t.boolean("lost_unmeasured_load_high");
  p.torque_lost_braking = t.boolean("lost_braking");
  p.torque_lost_braking_threshold = t.number("lost_braking_threshold", Range{0.0, 1.0, true, true});
  p.torque_loss_braking_threshold = t.number("loss_braking_threshold", Range{0.0, 1.0, true, true});
  p.torque_after_resolver_offset = t.boolean("after_resolver_offset");
  p.torque_stop_margin_rev = t.number("stop_margin_rev", config::Range::non_negative());
  p.unexplained_margin_Nm = t.number("unexplained_margin_Nm", pos);
  p.unexplained_relative = t.number("unexplained_relative", Range::closed(0.0, 10.0));
  p.unexplained_pull_fraction = t.boolean("unexplained_pull_fraction");
  p.unexplained_max_speed_rev_per_s = t.number("unexplained_max_speed_rev_per_s", pos);
  p.unexplained_persist_s = t.number("unexplained_persist_s", pos);
  p.seized_static_rev = t.number("seized_static_rev", pos);
  p.seized_window_s = t.number("seized_window_s", pos);
  p.seized_ramp_Nm = t.number("seized_ramp_Nm", pos);
  p.seized_force_error_kN = t.number("seized_force_error_kN", pos);
  p.seized_ramp_off_command_Nm = t.number("seized_ramp_off_command_Nm", config::Range::non_negative());
  t.finish();

  auto k = r.map("tracking");
  p.tracking_time_constant_s = k.number("time_constant_s", pos);
  p.tracking_threshold_kN = k.number("threshold_kN", pos);
  p.tracking_relative = k.number("relative", Range{0.0, 1.0, false, true});
  p.tracking_persist_s = k.number("persist_s", pos);
  p.tracking_full_speed_fraction = k.number("full_speed_fraction", config::Range::closed(0.0, 1.0));
  p.tracking_excess_position_bound = k.boolean("excess_position_bound");
  p.tracking_shortfall_position_bound = k.boolean("shortfall_position_bound");
  p.tracking_friction_after_restart = k.boolean("friction_after_restart");
  p.tracking_friction_as_subtracted = k.boolean("friction_as_subtracted");
  p.force_limit_kN = k.number("force_limit_kN", pos);
  p.release_min_speed_rev_per_s = k.number("release_min_speed_rev_per_s", pos);
  k.finish();

  auto l = r.map("link");
  p.deadline_s = l.number("deadline_s", pos);
  l.finish();
  r.finish();
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    r.fail("", e.what());
  }
  return p;
}

MonitorParams load_monitor_params(const std::string& file) {
  Reader r = Reader::from_file(file);
  return read_monitor_params(r);
}

}  // namespace bbw::faults
