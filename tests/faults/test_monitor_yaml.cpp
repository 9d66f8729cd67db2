// config/faults/monitor.yaml: the shipped file is the monitor's defaults, every field; bad files
// are refused with file, line, key and rule.
#include <gtest/gtest.h>

#include <string>

#include "bbw/faults/monitor_yaml.hpp"
#include "closed_loop.hpp"

namespace bbw::faults {

namespace {

std::string shipped_text() {
  std::FILE* f = std::fopen(test::source_path("config/faults/monitor.yaml").c_str(), "r");
  std::string s;
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) s.append(buf, n);
  std::fclose(f);
  return s;
}

std::string error_of(const std::string& text) {
  try {
    auto r = config::Reader::from_string(text, "monitor.yaml");
    read_monitor_params(r);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

}  // namespace

TEST(MonitorYaml, TheShippedFileIsTheMonitorsDefaults) {
  const MonitorParams y = load_monitor_params(test::source_path("config/faults/monitor.yaml"));
  const MonitorParams d;
#define SAME(f) EXPECT_EQ(y.f, d.f) << #f
  SAME(guard.position_min_rev); SAME(guard.position_max_rev); SAME(guard.speed_abs_max_rev_per_s);
  SAME(guard.load_cell_min_kN); SAME(guard.load_cell_max_kN); SAME(guard.current_abs_max_A);
  SAME(guard.max_sequence_jump); SAME(guard.max_time_jump_s); SAME(guard_position_from_eol); SAME(guard_diagnosed_load_cell_absent);
  SAME(lost_load_cell_curve_from_eol); SAME(calibrator_initial_curve_from_eol); SAME(calibrator_viscous_from_eol); SAME(calibrator_load_friction_from_eol); SAME(calibrator_backlash_from_eol); SAME(calibrator_range_from_eol); SAME(calibrator_elements_from_eol); SAME(calibrator_friction_from_eol); SAME(calibrator_friction_prior_weight); SAME(tracking_friction_as_subtracted); SAME(lost_resolver_friction_before_onset); SAME(lost_resolver_tracking_counts_friction);
  SAME(residual_threshold_kN); SAME(uncalibrated_residual_threshold_kN); SAME(residual_persist_s);
  SAME(residual_reference_s); SAME(residual_change_threshold_kN); SAME(curve_min_rev); SAME(curve_max_rev);
  SAME(residual_on_profile_corners); SAME(residual_findings); SAME(residual_low_upper_bound); SAME(residual_low_lower_bound); SAME(residual_low_static_span_rev);
  SAME(residual_sigma_factor); SAME(residual_stats_s); SAME(residual_stats_prior_s); SAME(residual_speed_kN_per_rev_per_s); SAME(residual_speed_free_rev_per_s);
  SAME(eol_band_kN); SAME(eol_relative); SAME(eol_speed_kN_per_rev_per_s); SAME(eol_friction_amplitude_factor);
  SAME(jump_threshold_rev); SAME(jump_confirm_s); SAME(jump_window_s); SAME(jump_max_gap_s); SAME(jump_compensate);
  SAME(stuck_samples); SAME(stuck_min_travel_rev); SAME(stuck_min_force_change_kN); SAME(frozen_attribution_samples);
  SAME(noise_window_samples); SAME(noise_step_kN); SAME(noise_second_difference_learn_s); SAME(noise_released); SAME(noise_min_fraction); SAME(dropout_samples); SAME(dropout_clear_samples);
  SAME(torque_per_A_Nm); SAME(Nm_per_kN); SAME(inertia_kg_m2);
  SAME(torque_filter_s); SAME(torque_check_min_load_kN); SAME(torque_check_min_torque_Nm);
  SAME(torque_fraction_threshold); SAME(torque_check_max_speed_rev_per_s); SAME(torque_check_moving_min_speed_rev_per_s); SAME(torque_check_moving_min_load_kN);
  SAME(torque_persist_s);
  SAME(torque_lost_threshold); SAME(torque_lost_persist_s); SAME(torque_loss_rescales_drive); SAME(torque_lost_unmeasured_load_high); SAME(torque_lost_braking); SAME(torque_lost_braking_threshold); SAME(torque_loss_braking_threshold); SAME(torque_check_moving_low_load_kN); SAME(torque_after_resolver_offset); SAME(torque_stop_margin_rev); SAME(unexplained_pull_fraction); SAME(seized_ramp_off_command_Nm);
  SAME(test_pulse_max_speed_rev_per_s); SAME(test_pulse_answer_ratio); SAME(test_pulse_unanswered); SAME(test_pulse_within_s);
  SAME(test_pulse_lost_mean_ratio); SAME(test_pulse_crossing_extremes); SAME(test_pulse_rescaled_after_loss); SAME(test_pulse_weak_count); SAME(test_pulse_weak_fraction);
  SAME(test_pulse_healthy_ratio); SAME(test_pulse_learn_count);
  SAME(tracking_time_constant_s); SAME(tracking_threshold_kN); SAME(tracking_relative); SAME(tracking_persist_s); SAME(tracking_excess_position_bound); SAME(tracking_shortfall_position_bound);
  SAME(tracking_friction_after_restart);
  SAME(force_limit_kN); SAME(release_min_speed_rev_per_s); SAME(deadline_s);
  SAME(residual_stats_clip); SAME(eol_friction_model_share); SAME(eol_creep_model); SAME(eol_friction_load_model); SAME(eol_thermal_offset_model); SAME(eol_viscous_model); SAME(eol_viscous_narrows_speed_allowance); SAME(eol_delay_model); SAME(eol_load_cell_delay_s); SAME(calibrated_two_friction_models); SAME(calibrated_capped_by_eol); SAME(eol_play_allowance);
  SAME(hold_kN); SAME(hold_speed_rev_per_s); SAME(hold_span_rev); SAME(hold_span_known_rev); SAME(hold_settle_samples); SAME(hold_settled_within_kN);
  SAME(hold_calibrated); SAME(hold_rebase); SAME(hold_friction_as_moved); SAME(hold_friction_swing); SAME(noise_paths_restart_learning); SAME(hold_restart_untrusted); SAME(hold_play_allowance); SAME(hold_play_allowance_over_span); SAME(residual_unseen_gap_forgets);
  SAME(revisit); SAME(revisit_kN); SAME(revisit_bin_rev); SAME(revisit_settle_samples); SAME(revisit_forget_s); SAME(modulation); SAME(modulation_time_constant_s); SAME(modulation_min_spread_rev_per_s);
  SAME(stuck_frozen_samples); SAME(stuck_frozen_run_factor); SAME(stuck_resolver_clear_samples);
  SAME(step_still_samples); SAME(step_still_span_rev); SAME(step_still_max_speed_rev_per_s); SAME(step_min_position_changes); SAME(step_kN); SAME(step_keep_fraction);
  SAME(unpowered_hold); SAME(unpowered_max_current_A); SAME(unpowered_settle_samples); SAME(unpowered_max_speed_rev_per_s); SAME(unpowered_coast_bound); SAME(unpowered_min_load_margin_kN); SAME(unpowered_kN);
  SAME(step_confirm_samples); SAME(step_moving); SAME(step_moving_resolver_stuck_pads_off); SAME(step_moving_window_samples); SAME(step_moving_quiet_fraction);
  SAME(step_moving_unexplained_rev); SAME(step_moving_speed_kN_per_rev_per_s);
  SAME(noise_second_difference_kN); SAME(noise_learned_factor); SAME(noise_learn_time_constant_s);
  SAME(unexplained_margin_Nm); SAME(unexplained_relative); SAME(unexplained_max_speed_rev_per_s); SAME(unexplained_persist_s);
  SAME(seized_static_rev); SAME(seized_window_s); SAME(seized_ramp_Nm); SAME(seized_force_error_kN);
  // Not in the file: the corner's end-of-line key-friction half-width and backlash (CcuCore sets
  // them from the scenario), the actuator test's current and length (the scenario's controller).
#undef SAME
}

TEST(MonitorYaml, BadFilesNameFileLineKeyAndRule) {
  const std::string ok = shipped_text();
  EXPECT_EQ(error_of(ok), "");
  const std::string unknown = error_of(replaced(ok, "  deadline_s: 0.015", "  deadline_s: 0.015\n  deadline_ms: 15"));
  EXPECT_NE(unknown.find("link.deadline_ms"), std::string::npos) << unknown;
  const std::string missing = error_of(replaced(ok, "  check_min_load_kN: 8.0\n", ""));
  EXPECT_NE(missing.find("torque.check_min_load_kN"), std::string::npos) << missing;
  EXPECT_NE(missing.find("missing"), std::string::npos) << missing;
  const std::string negative = error_of(replaced(ok, "threshold_kN: 0.6", "threshold_kN: -0.6"));
  EXPECT_NE(negative.find("monitor.yaml:"), std::string::npos) << negative;
  EXPECT_NE(negative.find("residual.threshold_kN"), std::string::npos) << negative;
  EXPECT_NE(negative.find("> 0"), std::string::npos) << negative;
  // A rule between fields (MonitorParams::validate) is refused too, naming the field.
  const std::string cross = error_of(replaced(ok, "uncalibrated_threshold_kN: 3.0", "uncalibrated_threshold_kN: 0.3"));
  EXPECT_NE(cross.find("uncalibrated_residual_threshold_kN"), std::string::npos) << cross;
}

}  // namespace bbw::faults
