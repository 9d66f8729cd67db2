// Analytic redundancy: r = (load cell - friction estimate) - curve(position) where the fitted
// curve is trusted (calibrated, inside the positions the fits had data for), against a threshold
// scaled by the fit's residual RMS; elsewhere (before the first fit, beyond the fitted range)
// r = load cell - end-of-line curve(position, temperature) against the end-of-line band
// (MonitorParams). A residual beyond its threshold, or (calibrated) a change against its own
// recent level beyond the change threshold, or (with an end-of-line curve) a change against its
// level where the drive has been before (the revisit rule) or since a hold settled (the hold rule),
// or, in a modulation, its fitted value at standstill beyond the threshold at standstill (the
// modulation rule), that persists is a disagreement; isolation names the channel that explains it
// (a frozen position: ResolverStuck; a frozen load cell: LoadCellStuck; a recent position jump:
// ResolverOffset; else LoadCellOffset). Feeds the noise detector with every residual above the
// trusted range, and below it (released) the load cell's own differences.
#pragma once

#include <cmath>
#include <limits>
#include <optional>
#include <tuple>
#include <vector>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/faults/detectors/detector.hpp"
#include "bbw/faults/detectors/jump_detector.hpp"
#include "bbw/faults/detectors/noise_detector.hpp"
#include "bbw/faults/detectors/stuck_detector.hpp"
#include "bbw/model/delay_line.hpp"
#include "bbw/plant/clamp_curve.hpp"
#include "bbw/plant/key_friction.hpp"

namespace bbw::faults {

struct MonitorParams;

class ResidualDetector {
 public:
  explicit ResidualDetector(const MonitorParams& p);
  // Steps the end-of-line friction model with every usable sample whose position is trusted,
  // whether or not the residual is judged (update() needs the calibrator's estimate, which a
  // load-cell dropout stops): a model left where the dropout began put the friction's whole
  // width into the residual when the load cell came back after the position had reversed
  // (tuning seed 1401 run 244: load_cell_offset 20 ms after a 1.9 s dropout cleared).
  void track_position(const CornerReading& r, const MonitorParams& p);
  // The position is not trusted (the resolver diagnosed): the friction model's state is lost
  // with it and is found again by sweeping once the position is back.
  void forget_position() {
    // The bins learn only where the position is tracked: once forgotten, they are already clear
    // (called every sample while the resolver is diagnosed).
    if (have_x_) clear_revisit();
    friction_known_ = false;
    have_x_ = false;
    lagged_.clear();
  }
  // Call track_position() first with the same sample.
  void update(const CornerReading& r, const calibration::Estimate& e, const MonitorParams& p, DiagnosisArbiter& a,
              NoiseDetector& noise, const StuckDetector& stuck, const JumpDetector& jump);
  void on_rejoin() {
    restart_rules();
    forget_position();  // the positions in the gap are unknown: so is the friction's state
    have_saved_ = false;
  }
  // The rules' references and persistence start again (the position moved under them).
  void restart_rules() {
    suspect_ = false;
    low_suspect_ = false;
    hold_ref_ = false;
    hold_slow_ = 0;
    hold_sum_kN_ = 0.0;
    static_ref_ = false;
    static_count_ = 0;
    mod_definition_ = -1;
  }
  // The position's state (the end-of-line friction model, the play, the sweep) before a resolver
  // jump: taken back once the jump is confirmed as an offset, from where the positions less the
  // offset go on (the Maxwell-slip model is rate-independent: the samples between the jump and
  // its confirmation are one step). Without a saved state: forgotten. (The copy's storage is
  // made at construction: no allocation per sample.)
  void save_position() {
    saved_ = position_state();
    have_saved_ = true;
  }
  void restore_position() {
    clear_revisit();  // the samples since the jump were learnt at the wrong position
    if (have_saved_) position_state() = saved_;
    else forget_position();
    lagged_.clear();  // the positions since the jump were the wrong ones
  }
  // Whether the end-of-line friction model's state is known (the position has swept twice its
  // largest threshold since the start or the last gap), and its friction (kN).
  bool eol_friction_known() const { return friction_known_; }
  double eol_friction_kN() const { return eol_friction_kN_; }
  void set_curve_range(double min_rev, double max_rev) {
    curve_min_rev_ = min_rev;
    curve_max_rev_ = max_rev;
  }
  // At an accepted fit: its residual RMS (a floor of the calibrated thresholds' sigma). What keeps
  // a slow fault from widening the learnt statistics is residual_stats_clip.
  void set_fit_rms(double fit_rms_kN) {
    fit_rms_kN_ = fit_rms_kN;
    hold_refit_ = true;  // a new fit moves the calibrated residual by itself: the hold restarts (or rebases)
  }
  // Whether the calibrated residual may use the last accepted fit (FaultMonitor::set_fit_friction_amplitude).
  void set_fit_credible(bool credible) { fit_credible_ = credible; }
  bool fit_credible() const { return fit_credible_; }
  double residual_kN() const { return residual_kN_; }
  // The threshold the last residual was held against (kN).
  double threshold_kN() const { return threshold_kN_; }
  // The change threshold the last change was held against (kN; NaN where there is no change rule).
  double change_threshold_kN() const { return change_threshold_kN_; }
  // A disagreement is under way but not yet confirmed (persist_s).
  bool suspect() const { return suspect_; }
  double change_kN() const { return change_kN_; }
  // The residual's change since the hold settled (NaN outside a hold).
  double hold_change_kN() const { return hold_change_kN_; }
  // The most clamp force the end-of-line curve allows at the last sample's position (the motor's
  // plus half the play, its creep; + relative, band and speed terms); NaN without a curve.
  double clamp_upper_kN() const { return clamp_upper_kN_; }
  // The least: the curve at the motor's position less half the play, less the same terms.
  double clamp_lower_kN() const { return clamp_lower_kN_; }
  // The allowance that change was held against (kN; NaN outside a hold).
  double hold_threshold_kN() const { return hold_threshold_kN_; }
  // The revisit rule's change against the bin's level and its allowance (kN; NaN where the bin
  // has no level yet or the rule is off).
  double revisit_change_kN() const { return revisit_change_kN_; }
  double revisit_threshold_kN() const { return revisit_threshold_kN_; }
  double modulation_kN() const { return modulation_kN_; }
  double modulation_threshold_kN() const { return modulation_threshold_kN_; }

 private:
  bool suspect_ = false;
  // The rule below the trusted range (residual_low_upper_bound): its own persistence.
  bool low_suspect_ = false;
  double low_onset_s_ = 0.0;
  // Its still-drive rule (residual_low_static_span_rev): samples averaged, the settled level,
  // where the motor settled and the curve there.
  bool static_ref_ = false;
  int static_count_ = 0;
  double static_sum_kN_ = 0.0;
  double static_level_kN_ = 0.0;
  double static_x0_rev_ = 0.0;
  double static_curve_kN_ = 0.0;
  // Below the trusted range: whether the load cell left the still drive's level (curve_kN: the
  // end-of-line curve at the motor's position).
  bool static_changed(const CornerReading& r, double curve_kN, const MonitorParams& p);
  // Names the channel that explains a disagreement that began at onset_s and confirms it.
  void isolate(double onset_s, double t, const MonitorParams& p, DiagnosisArbiter& a, const StuckDetector& stuck,
               const JumpDetector& jump) const;
  bool fit_credible_ = true;
  double onset_s_ = 0.0;
  double residual_kN_ = std::numeric_limits<double>::quiet_NaN();
  double change_kN_ = std::numeric_limits<double>::quiet_NaN();
  bool have_reference_ = false;
  bool reference_calibrated_ = false;  // the calibrator's state when the reference was set
  double reference_kN_ = 0.0;
  double reference_speed_rev_per_s_ = 0.0;  // the speed low-passed and frozen as reference_kN_
  double reference_time_s_ = 0.0;
  double curve_min_rev_;
  double curve_max_rev_;
  double trusted_min_rev_;  // the calibrator's range: below it no rule (contact, soft pads)
  double fit_rms_kN_ = 0.0;
  double threshold_kN_ = std::numeric_limits<double>::quiet_NaN();
  double change_threshold_kN_ = std::numeric_limits<double>::quiet_NaN();
  bool eol_mode_ = false;   // the last residual was against the end-of-line curve
  // The corner's healthy calibrated residual: mean squares of the residual and of its change
  // (low-passed over residual_stats_s, while nothing is suspected; NaN until calibrated).
  double ms_residual_kN2_ = std::numeric_limits<double>::quiet_NaN();
  double ms_change_kN2_ = std::numeric_limits<double>::quiet_NaN();
  double stats_time_s_ = 0.0;
  double stats_learnt_s_ = 0.0;  // healthy time learnt since the statistics started
  double stats_clip_moment_ = 1.0;  // E[min(X^2, stats_clip^2)], X a unit Gaussian
  std::optional<plant::ClampCurve> eol_;
  // The caliper's end-of-line key-friction model (Maxwell-slip elements as its production line
  // identified them), driven by the measured position.
  std::optional<plant::KeyFriction> eol_friction_;
  double sweep_rev_ = 0.0;   // twice its largest threshold
  double eol_friction_half_width_kN_ = 0.0;  // the model's (its elements' K x threshold)
  bool friction_known_ = false;
  bool have_x_ = false;
  double x_min_rev_ = 0.0, x_max_rev_ = 0.0;  // since the start or the last gap
  double eol_friction_kN_ = 0.0;
  double spindle_rev_ = 0.0;  // the play operator's state (backlash)
  // With a load-cell lag (MonitorParams::eol_delay_model): the positions, read eol_load_cell_delay_s
  // back (lag_s_ > 0). The position the last load-cell reading belongs to (track_position's: the
  // sample's own without a lag).
  double lag_s_ = 0.0;
  model::DelayLine lagged_{2};
  double x_lc_rev_ = 0.0;
  bool spindle_moved_ = true;  // in the last sample (the viscous term's; MonitorParams::eol_viscous_model)
  // The position's state, one list for saving and taking it back.
  std::tuple<std::optional<plant::KeyFriction>&, bool&, bool&, double&, double&, double&, double&> position_state() {
    return std::tie(eol_friction_, friction_known_, have_x_, x_min_rev_, x_max_rev_, eol_friction_kN_, spindle_rev_);
  }
  std::tuple<std::optional<plant::KeyFriction>, bool, bool, double, double, double, double> saved_{std::nullopt, false, false, 0.0, 0.0, 0.0, 0.0};
  bool have_saved_ = false;
  // The hold rule's reference: the residual's level once the hold settled.
  bool hold_ref_ = false;
  bool hold_eol_mode_ = false;
  bool hold_known_ = false;  // the friction model's state was known when the reference was set
  int hold_slow_ = 0;
  double hold_sum_kN_ = 0.0;
  double hold_settle_min_kN_ = 0.0, hold_settle_max_kN_ = 0.0;  // the settle samples' residuals
  double hold_r0_kN_ = 0.0;
  double hold_x0_rev_ = 0.0;
  double hold_f0_kN_ = 0.0;
  double hold_friction0_kN_ = 0.0;  // the end-of-line friction model's when the hold settled
  bool hold_friction_ref_ = false;   // ... and whether its state was known then (and since)
  double hold_change_kN_ = std::numeric_limits<double>::quiet_NaN();
  double hold_threshold_kN_ = std::numeric_limits<double>::quiet_NaN();
  bool hold_refit_ = false;  // a fit was accepted since the last sample
  // The last sample's residual (NaN when it was not slow), key position and curve, for a rebase.
  double hold_last_kN_ = std::numeric_limits<double>::quiet_NaN();
  double hold_last_x_rev_ = 0.0;
  double hold_last_curve_kN_ = 0.0;
  // The key positions the hold has spanned since it began settling, and the load scale then
  // (MonitorParams::hold_friction_swing).
  double hold_x_min_rev_ = 0.0, hold_x_max_rev_ = 0.0;
  double hold_scale0_ = 1.0;
  // The most the end-of-line friction model's elements can move over a span of positions:
  // sum K_i min(2 Delta_i, span) (kN, unscaled).
  double friction_swing_kN(double span_rev) const;
  // The clamp force's bounds at the last sample's position (clamp_upper_kN(), clamp_lower_kN()).
  double clamp_upper_kN_ = std::numeric_limits<double>::quiet_NaN();
  double clamp_lower_kN_ = std::numeric_limits<double>::quiet_NaN();
  // The key friction's growth with the clamp force (MonitorParams::eol_friction_load_gain), this
  // sample's: the end-of-line friction model's force and its half-width times it.
  double friction_scale_ = 1.0;
  double scaled_friction_kN() const { return eol_friction_kN_ * friction_scale_; }
  double scaled_half_width_kN(const MonitorParams& p) const;
  // The pads' creep model (MonitorParams::eol_creep_fraction), stepped with the position.
  void step_creep(double x_rev, const CornerReading& r, const MonitorParams& p);
  bool have_creep_ = false;
  double creep_kN_ = 0.0, creep_curve_kN_ = 0.0, creep_time_s_ = 0.0;
  // The revisit rule (MonitorParams::revisit): per position bin and class (moving up, down or
  // slow; the keys all slipping one way or between), the healthy residual's level and the speed
  // it was learnt at. Sized at construction.
  static constexpr std::size_t kRevisitClasses = 6;
  struct RevisitBin {
    int n = 0;
    double level_kN = 0.0;
    double speed_rev_per_s = 0.0;
  };
  std::vector<RevisitBin> revisit_bins_;
  int revisit_per_class_ = 0;  // bins per class from curve_min_rev
  double revisit_kN_ = std::numeric_limits<double>::quiet_NaN();  // its residual (end-of-line curve and friction)
  double revisit_time_s_ = 0.0;
  // The load cell's previous reading and its time (the released noise path, below the trusted range).
  double prev_lc_kN_ = std::numeric_limits<double>::quiet_NaN();
  double prev_lc_time_s_ = 0.0;
  double revisit_change_kN_ = std::numeric_limits<double>::quiet_NaN();
  double revisit_threshold_kN_ = std::numeric_limits<double>::quiet_NaN();
  // The modulation rule (MonitorParams::modulation): exponentially weighted sums of the fit.
  struct ModulationSums {
    double w = 0, v = 0, s = 0, vv = 0, vs = 0, r = 0, rv = 0, rs = 0, pos = 0;
  };
  ModulationSums mod_;
  int mod_definition_ = -1;
  double mod_time_s_ = 0.0;
  double modulation_kN_ = std::numeric_limits<double>::quiet_NaN();
  double modulation_threshold_kN_ = std::numeric_limits<double>::quiet_NaN();
  // Adds the sample and judges the fit's residual at standstill against thr0_kN.
  bool judge_modulation(double residual_kN, double speed_rev_per_s, double t, int definition, double thr0_kN,
                        const MonitorParams& p);
  void clear_revisit() {
    for (RevisitBin& b : revisit_bins_) b = RevisitBin{};
  }
  // Judges the residual against its bin's level (sets revisit_change_kN_ and revisit_threshold_kN_);
  // returns the bin (-1: none) for learn_revisit().
  int judge_revisit(const CornerReading& r, double eol_keys_kN, bool& over, const MonitorParams& p);
  void learn_revisit(int bin, double speed_rev_per_s, double dt_s, const MonitorParams& p);
};

}  // namespace bbw::faults
