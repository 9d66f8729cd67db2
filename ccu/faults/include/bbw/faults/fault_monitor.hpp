// Per-corner fault detection and isolation in the CCU (docs/faults.md, "Detection"): one
// detector per fault family (bbw/faults/detectors/: dropout, stuck channels, resolver jump,
// residual with noise, actuator torque balance, tracking, link) and an arbiter that latches each
// part's Diagnosis. Every threshold is a MonitorParams field, loaded from
// config/faults/monitor.yaml (bbw/faults/monitor_yaml.hpp). Pure: no DDS, clock, file or thread;
// time comes with the samples and with tick(now_s). Memory is sized at construction; update()
// and tick() do not allocate.
//
// Fed, per sample, the guard's verdict, the reading and (when the calibrator was fed it) the
// calibrator's estimate; fed link events from outside (DDS deadline / liveliness, or the
// in-memory runner). Each part's first confirmed fault is latched; link and process losses
// clear when samples arrive again.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <optional>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/faults/reading.hpp"
#include "bbw/faults/sample_guard.hpp"
#include "bbw/faults/schedule.hpp"
#include "bbw/faults/arbiter.hpp"
#include "bbw/faults/detectors/dropout_detector.hpp"
#include "bbw/faults/detectors/jump_detector.hpp"
#include "bbw/faults/detectors/link_detector.hpp"
#include "bbw/faults/detectors/noise_detector.hpp"
#include "bbw/faults/detectors/residual_detector.hpp"
#include "bbw/faults/detectors/stuck_detector.hpp"
#include "bbw/faults/detectors/moving_step_detector.hpp"
#include "bbw/faults/detectors/step_detector.hpp"
#include "bbw/faults/detectors/torque_detector.hpp"
#include "bbw/faults/detectors/tracking_detector.hpp"
#include "bbw/faults/detectors/unpowered_hold_detector.hpp"
#include "bbw/faults/finding.hpp"
#include "bbw/plant/params.hpp"

namespace bbw::faults {

struct MonitorParams {
  GuardLimits guard;
  // With an end-of-line curve, a corner's guard takes positions up to where that curve (at its
  // reference temperature) reaches the load cell's range, guard.load_cell_max_kN, when that is
  // beyond guard.position_max_rev, and so does its calibrator: a caliper ten times softer than
  // the shipped one needs 11-12 rev for 16-20 kN, and the guard rejected every sample up there as
  // corrupt (soft10 campaigns: faults in hard stops unseen, healthy samples counted as corrupt).
  bool guard_position_from_eol = true;
  // Once the load cell is named faulty, its value out of the guard's range makes that channel
  // absent rather than the sample corrupt (SampleGuard::check's load_cell_diagnosed). Off: a
  // drifting load cell past -10 kN made every later sample corrupt.
  bool guard_diagnosed_load_cell_absent = true;

  // Analytic redundancy: r = (load cell - friction estimate) - curve(position).
  double residual_threshold_kN = 0.6;               // once the calibrator has an accepted fit
  double uncalibrated_residual_threshold_kN = 3.0;  // before it (initial curve, no friction model)
  double residual_persist_s = 0.02;
  // A change of the residual against its own recent level (a low-pass with this time constant,
  // frozen while a fault is suspected) beyond residual_change_threshold_kN is also a
  // disagreement (once calibrated): it catches a step whose sign the standing calibration error
  // partly cancels, or that the local loop's reaction partly hides.
  double residual_reference_s = 0.1;
  double residual_change_threshold_kN = 0.45;
  // Once calibrated, both thresholds scale with the corner's own model uncertainty (never below
  // the fixed values above): residual_sigma_factor times the larger of the residual RMS of its
  // last accepted fit and the RMS of its own healthy residual (resp. of the residual's change)
  // over residual_stats_s, updated only while nothing is suspected. docs/faults.md, "Thresholds".
  double residual_sigma_factor = 4.0;
  double residual_stats_s = 5.0;
  // The starting value (the end-of-line band) weighs as this much healthy residual (issue 14,
  // thirteenth session): the learning is the running mean of the start and the samples until
  // they span residual_stats_s, exponential over residual_stats_s after. (Exponential from the
  // start, the band took about 15 s to fall to a well-fitted corner's 4 sigma: drifts after the
  // first fit met thresholds of 1.3-1.8 kN. residual_stats_prior_s >= residual_stats_s: that.)
  double residual_stats_prior_s = 0.5;
  // A sample adds at most residual_stats_clip^2 times the learnt mean square (0: no bound), so a
  // slow fault under the threshold cannot widen it as fast as it grows.
  double residual_stats_clip = 1.5;
  double residual_speed_kN_per_rev_per_s = 0.3;  // added to both, times |speed| beyond:
  double residual_speed_free_rev_per_s = 3.0;
  // The end-of-line curve: the caliper's own clamp curve with its temperature coefficients, as
  // measured at the end of its production line (CcuCore sets it from the scenario's plant, as it
  // sets the actuator model; absent: the rule is off). Before the first accepted fit, and
  // outside the positions the fits had data for (a hard stop beyond them), the residual is
  // load cell - eol(position, measured temperature) against the band
  //   eol_friction_half_width_kN + eol_band_kN + eol_relative |eol| + eol_speed |speed|
  // (key friction not yet modelled, noise, the curve's spread with temperature and ageing,
  // unmodelled speed effects: viscous friction, sensor delay).
  std::optional<plant::ClampCurveParams> eol_curve;
  double eol_friction_half_width_kN = 1.0;
  // The caliper's end-of-line key-friction model (its elements, as identified on the production
  // line; CcuCore sets the scenario's): once its state is known the end-of-line residual
  // subtracts its friction and the band holds eol_friction_model_share x the half-width instead
  // of the whole width.
  std::optional<plant::KeyFrictionParams> eol_key_friction;
  double eol_friction_model_share = 0.25;
  // Calibrated, once the end-of-line friction model's state is known: the residual is the one of
  // the two friction models' (the calibrator's, the end-of-line one) nearest zero, 0 when they
  // bracket it (a load-cell fault moves the load cell against both).
  bool calibrated_two_friction_models = true;
  // Calibrated, once that state is known: the thresholds learnt from the corner's own residual
  // never exceed the end-of-line band (friction model share, band, relative, speed). A fit can
  // only make the monitor know the caliper better than its end-of-line data, and the learnt
  // statistics could follow a slow drift while the brake modulates (tune_bias run 145: a
  // 1.2 kN/s drift in ABS braking, threshold 1.9 -> 8.7 kN in 3.4 s, never named).
  bool calibrated_capped_by_eol = true;
  // On a caliper with backlash, before the play's state is known (the end-of-line curve is read at
  // the motor's position): the end-of-line band adds what the curve can change between the
  // motor's position and the furthest the spindle can be from it (half the play). Without, a loop
  // that moved the motor 0.053 rev back across the play of a caliper ten times stiffer, the clamp
  // force standing, moved the residual by 1.4 kN past the band (stiff10 run 13: load_cell_offset).
  bool eol_play_allowance = true;
  // The caliper's backlash between the motor (the resolver) and the spindle (the keys, the
  // pads), as its end-of-line test measured it (CcuCore sets the corner's; 0: none).
  double eol_backlash_rev = 0.0;
  // The pads' creep (a standard linear solid: a change of the relaxed curve force adds
  // f / (1 - f) of itself, which relaxes with the time constant), as the caliper's end-of-line
  // test measured it (CcuCore sets the corner's; fraction 0: none). With eol_creep_model every
  // end-of-line curve force the residual rules use includes it (without, a caliper with creep
  // raised load_cell_offset in 23 of 30 fault-free runs: its hold relaxes by the fraction).
  bool eol_creep_model = true;
  // Keys whose friction grows with the clamp force (the plant's load-dependent friction: key
  // friction x (1 + gain F / reference)), as the end-of-line test measured it (CcuCore sets the
  // corner's; gain 0: none): with eol_friction_load_model the residual rules' friction model and
  // its bands scale with the force.
  bool eol_friction_load_model = true;
  // A load cell whose offset moves with temperature (the plant's thermal drift: k (T - T_ref)), as
  // the end-of-line test measured it (CcuCore sets the corner's; 0: none): with
  // eol_thermal_offset_model the residual rules expect it in the load cell's reading.
  bool eol_thermal_offset_model = true;
  // The drive's viscous friction (the plant's c_v v, on the spindle's speed), as the end-of-line
  // test measured it (CcuCore sets the corner's; 0: none; a calibrator's own viscous term is taken
  // out of its friction where they meet): with eol_viscous_model the residual rules expect it in the load cell's reading
  // while the spindle moves (the motor's measured speed, 0 while the motor crosses the play).
  // Without, a calibrated viscous caliper reversing from a -2 rev/s release into a +2.7 rev/s
  // apply moved its residual by 0.55 kN against the change rule's 0.48 kN (extreme hunt seed 2613
  // run 18, a fault-free finding).
  bool eol_viscous_model = true;
  // ... and the residual rules' speed allowances, for speed effects no model carries, are narrowed
  // by the viscous term the model carries (FaultMonitor takes it out of residual_speed_kN_per_rev_per_s
  // and eol_speed_kN_per_rev_per_s, and sets the coefficient to 0 where the model is off).
  bool eol_viscous_narrows_speed_allowance = true;
  double eol_viscous_kN_per_rev_per_s = 0.0;
  // The load cell's lag behind the resolver (the plant's sensor delay), as the end-of-line test
  // measured it (CcuCore sets the corner's; 0: none, at most 0.05 s). With eol_delay_model the
  // end-of-line model (its friction, the play, the curve where the keys are) follows the position
  // that much earlier, the one the load cell's reading belongs to. Without, the model's keys
  // flipped 5 ms before the load cell at each reversal of an ABS modulation: a soft caliper's 4 kN
  // keys made steps of the residual that named a healthy load cell noisy (soft10 run 29).
  bool eol_delay_model = true;
  double eol_load_cell_delay_s = 0.0;
  double eol_load_cell_kN_per_C = 0.0;
  double eol_load_cell_reference_C = 40.0;
  double eol_friction_load_gain = 0.0;
  double eol_friction_reference_kN = 40.0;
  double eol_creep_fraction = 0.0;
  double eol_creep_time_constant_s = 1.0;
  // Hold rule: slower than hold_speed_rev_per_s for hold_settle_samples sets the residual's
  // reference level (their mean); while the position stays within hold_span_rev of it, a change
  // beyond hold_kN + eol_relative x the curve's change + the friction's uncertainty (end of line:
  // its model share or its whole width) is a disagreement.
  double hold_kN = 0.5;
  double hold_speed_rev_per_s = 0.5;
  double hold_span_rev = 0.1;
  // ... or within hold_span_known_rev once the end-of-line friction model's state is known (and
  // was when the hold settled): the model follows the keys' friction through any travel, within
  // its share; the span then only bounds how far the curve's relative accuracy is trusted.
  double hold_span_known_rev = 0.3;
  int hold_settle_samples = 20;
  // The hold's reference is set only from settle samples whose residuals lie within this of each
  // other (0: any): a residual still moving has not settled. Else the settling starts again from
  // the newest sample (a 5 ms load-cell delay on a caliper whose keys had just reversed: the
  // residual fell 1.3 kN across the settle samples, their mean was 0.85 kN above the level it came
  // to, and load_cell_offset was named; soft10_ff run 2).
  double hold_settled_within_kN = 0.5;
  // The hold rule on calibrated corners too (with an end-of-line curve): the learnt residual
  // statistics follow a slow drift the loop absorbs by creeping; the hold's level does not.
  bool hold_calibrated = true;
  // A settled hold carries its change across a change of the residual's definition or a new
  // fit (its reference moves by the residual's jump between two samples) instead of restarting.
  bool hold_rebase = true;
  // The hold's friction allowance: the friction model's share of what its friction moved since
  // the hold settled (at most the width), instead of the share of the whole width.
  bool hold_friction_as_moved = true;
  // Before the end-of-line friction model's state is known, the hold's friction allowance is the
  // most the model's Maxwell-slip elements can move over the positions the hold has spanned,
  // sum K_i min(2 Delta_i, max x - min x) (times the load scale, plus the scale's own change
  // times the half-width), instead of one half-width: a slow reversal within a hold swings the
  // keys by up to twice the half-width; a hold that stays put, by almost nothing.
  bool hold_friction_swing = true;
  // The hold restarts wherever the residual is not judged (below the trusted range, no curve), as
  // the change rule's reference does: its level and the positions it spanned hold only for the
  // samples it saw.
  bool hold_restart_untrusted = true;
  // On a caliper with backlash, before the play's state is known (the hold's position is the
  // motor's): the hold's allowance adds the curve's change over the positions the motor moved
  // since the hold settled, at most its change across the play (the spindle, and the clamp force,
  // may have stood while the motor crept inside the play). Without, a force loop creeping the motor
  // 0.015 rev inside the play at a constant clamp force moved the residual by -0.77 kN on a caliper
  // ten times stiffer (stiff10_ff runs 1, 129, 189).
  bool hold_play_allowance = true;
  // ... the curve's span over the positions the motor took in the hold (its lowest to its
  // highest), not its net change: a motor that went down and back up inside the play has crossed
  // it, the spindle standing. Without, a loop hunting 0.05 rev in the play of a caliper ten times
  // stiffer moved the residual by 1.1 kN at a net 0.2 kN change of the curve (stiff10 run 339,
  // fault-free: load_cell_offset on RR and RL).
  bool hold_play_allowance_over_span = true;
  // Usable samples more than jump_max_gap_s apart (those between rejected by the guard, e.g. a
  // position beyond its range): the positions between went unseen, so the end-of-line friction
  // model's state (the play's, the sweep's) is forgotten and the rules' references restart, as
  // after a link outage. Without, a caliper that travelled beyond the guard's 10 rev and came back
  // reversing judged its keys' reversal (2 x 4 kN) as a load-cell offset (soft10_ff).
  bool residual_unseen_gap_forgets = true;
  // Revisit rule: where the drive has been before, the load cell against the end-of-line curve
  // and friction model keeps the level it had there (the curve and the friction are the same
  // there, a load-cell drift is not). Per position bin of revisit_bin_rev and class (moving up,
  // down or slower than hold_speed_rev_per_s; the model's keys all slipping one way or between),
  // a bin's level is the mean of its first revisit_settle_samples healthy residuals, then
  // low-passed over revisit_forget_s of time spent in it. A change beyond revisit_kN +
  // eol_speed x the speed's change from the bin's (+ the friction model's share of the width
  // when between) is a disagreement. The bins start again when the position is lost or restored.
  bool revisit = true;
  double revisit_kN = 0.6;
  double revisit_bin_rev = 0.05;
  int revisit_settle_samples = 5;
  double revisit_forget_s = 20.0;
  // The modulation rule (twenty-second session): the level rule's threshold grows with speed
  // (unmodelled viscous friction, sensor delay), so in ABS-like modulation at 5-8 rev/s a drift is
  // over the threshold only around the reversals, never for residual_persist_s. Those effects go
  // with the speed (and the keys' with its sign), a load-cell fault does not: over the last
  // modulation_time_constant_s (exponentially weighted) the residual is fitted as c + a v +
  // b sign(v), and c, the residual at standstill, is judged against the level rule's threshold at
  // standstill. Only while the speeds spread by modulation_min_spread_rev_per_s (weighted standard
  // deviation) or more, with at least a fifth of the weight each way; the fit restarts when the
  // residual's definition changes.
  bool modulation = true;
  double modulation_time_constant_s = 0.2;
  double modulation_min_spread_rev_per_s = 1.0;
  double eol_band_kN = 0.5;
  // The end-of-line test's accuracy, relative to the force: its reference load cell and the
  // temperature compensation (1 %; in simulation the end-of-line curve is the plant's own, so
  // 0-3 % raised no fault-free finding on the three fault-free populations: not set by them).
  double eol_relative = 0.01;
  double eol_speed_kN_per_rev_per_s = 0.3;
  // A fit is credible when its friction amplitude (the sum of its elements' amplitudes: the most
  // friction it can give) is at most this times the caliper's key-friction half-width. A fit
  // beyond it explains more as friction than the caliper's keys can hold (viscous friction,
  // backlash or a short cycle taken for friction; seen up to 5x on the tuning population): its
  // friction and curve are wrong by up to that much, so until a credible fit the residual is
  // held against the end-of-line band, as before the first fit (issue 14). Only with an
  // end-of-line curve.
  double eol_friction_amplitude_factor = 1.5;
  // Where the curve is trusted: the calibrator's range (CornerSupervisor copies x_min_rev and
  // x_max_rev of the calibrator config here). Outside it the cubic is an extrapolation.
  double curve_min_rev = 1.0;
  double curve_max_rev = 6.0;
  // Whether residual disagreements become findings on corners that follow their own position
  // profile (the paper's rig: 30-60 C, up to 12 rev/s, no command to react with). The residual
  // is still computed (and feeds the noise detector) when this is false. CcuCore applies it.
  bool residual_on_profile_corners = false;
  bool residual_findings = true;  // set per corner by CcuCore from the rule above
  // Below the trusted range, with an end-of-line curve: a load cell that reads more than the
  // curve at the position (plus half the drive's play, at least 0) + the key friction's
  // half-width + eol_band_kN + eol_relative x that force + the speed term names a load-cell
  // offset. One-sided: wear moves the contact point later, so the curve bounds the force from
  // above only. A positive drift the loop follows by releasing drives the pads below the trusted
  // range, where the two-sided rules do not look (tune_bias run 73).
  bool residual_low_upper_bound = true;
  // ... and from below, wherever the pads are: the clamp force is never negative, so a load cell
  // more than the key friction's half-width + the band below 0 reads an offset.
  bool residual_low_lower_bound = true;
  // ... and, there, a drive that does not move: while the motor's position stays within
  // residual_low_static_span_rev of where it settled (hold_speed_rev_per_s, hold_settle_samples),
  // the keys cannot slip and the pads cannot move, so the load cell keeps its level within
  // hold_kN + eol_relative x the curve's change (the temperature) + the speed term (a drift on a
  // seized caliper at the pads' contact, tuning seed 1401 run 57). 0: off.
  double residual_low_static_span_rev = 5.0e-4;

  // Resolver consistency: a position step the measured speed does not explain.
  double jump_threshold_rev = 0.01;
  double jump_confirm_s = 0.01;     // a jump not undone within this is an offset
  double jump_window_s = 0.05;      // a jump this recent explains a residual as the resolver's
  double jump_max_gap_s = 0.003;    // no prediction across a longer gap between usable samples
  // After a resolver offset is named, the residual rules go on against the position less the
  // offsets the confirmed jumps measured (the end-of-line curve and its band, as before a fit):
  // a load-cell fault on the same corner stays visible. A stuck resolver has no such position.
  bool jump_compensate = true;

  // Stuck channels: exactly repeated readings while the other channel moves.
  int stuck_samples = 20;
  double stuck_min_travel_rev = 0.05;         // position range that must move a load cell
  double stuck_min_force_change_kN = 1.0;     // load-cell range that must move a resolver
  int frozen_attribution_samples = 5;
  // Frozen at any motion: the load cell, or the resolver's position and speed together, repeated
  // exactly over stuck_frozen_samples (a live channel's noise never repeats an unquantised value:
  // the load cell and the speed are not quantised, the position's noise is about its quantum) and
  // over stuck_frozen_run_factor x the longest run the channel has repeated by itself (learnt: a
  // quantised or quiet channel repeats; 0: the rule off).
  int stuck_frozen_samples = 20;
  double stuck_frozen_run_factor = 3.0;
  // A stuck resolver that lives again: its speed (unquantised, noisy) changed in each of this
  // many consecutive samples. The finding is cleared (the calibrator and the residual resume);
  // a resolver offset is never cleared (a live reading is not a right one).
  int stuck_resolver_clear_samples = 200;

  // Load-cell step at standstill (StepDetector): the position within step_still_span_rev over
  // step_still_samples, then the load cell off that window's mean by step_kN and beyond
  // step_keep_fraction of it for step_confirm_samples more: LoadCellOffset.
  int step_still_samples = 10;
  double step_still_span_rev = 5e-4;
  // ... and every sample's measured speed within this (0: not judged): a drive stopped within a
  // sample stands still from it on while the sample's load cell still carries its speed's viscous
  // term (effects campaign run 132: a seizure at 25 rev/s on a viscous caliper, 5 kN).
  double step_still_max_speed_rev_per_s = 1.0;
  int step_min_position_changes = 3;          // in the window and the sample: a frozen resolver is not a still actuator
  double step_kN = 0.5;
  double step_keep_fraction = 0.6;
  int step_confirm_samples = 5;         // repeats that name the frozen channel of a residual
  // The still window's level may also move by the end-of-line keys' whole stiffness (every
  // element sticking) x the window's travel, with the sample judged: a drive standing within a
  // few still spans (across a test pulse) still turns its key friction by that much. Without it a
  // healthy caliper with stiff keys (the stress population's) crept back 1 mrev after a pulse
  // in a 12 kN hold, its load cell fell 0.52 kN with the friction, and the still rule named it a
  // load-cell offset (stress seed 1406 run 311). Off: step_kN alone.
  bool step_friction_allowance = true;
  // Moving (MovingStepDetector, with an end-of-line curve and key-friction model, beyond its
  // contact point): the load cell against the end-of-line curve leaves the straight line through
  // its last step_moving_window_samples values by step_kN + 4x their spread about it + the key
  // friction's largest change over the travel + the curve's largest change in the window +
  // step_moving_speed_kN_per_rev_per_s x the largest speed change; only while that spread is at
  // most step_moving_quiet_fraction x step_kN, never across a position step the speed does not
  // explain by step_moving_unexplained_rev. Then kept as the still rule's step: LoadCellOffset.
  bool step_moving = true;
  int step_moving_window_samples = 20;
  double step_moving_quiet_fraction = 0.25;
  double step_moving_unexplained_rev = 0.003;
  double step_moving_speed_kN_per_rev_per_s = 0.3;
  // The moving rule judges also a rise toward 0 from below it (not past it by more than step_kN)
  // while the resolver is named stuck (false: not judged; the pads are off, and the spindle's
  // friction vanishes when the drive's unseen motion stops).
  bool step_moving_resolver_stuck_pads_off = false;

  // A load cell on a corner whose resolver is named stuck while the drive held (its frozen speed
  // within unpowered_max_speed_rev_per_s; a rotor frozen at speed coasts on for up to 0.2 s with
  // the force rising), its motor unpowered (the current within unpowered_max_current_A)
  // (UnpoweredHoldDetector): the mean of the last unpowered_settle_samples load-cell values is the
  // reference while it is at a load the pads surely carry (eol_friction_half_width_kN + eol_band_kN
  // + unpowered_min_load_margin_kN); it follows that mean down, never up, and a load cell above it
  // by more than unpowered_kN for residual_persist_s is a LoadCellOffset (a held drive without
  // current keeps its clamp force or the load drives it back; nothing raises it).
  bool unpowered_hold = true;
  double unpowered_max_current_A = 0.5;
  double unpowered_max_speed_rev_per_s = 0.5;
  // The speed held to unpowered_max_speed_rev_per_s is also a bound on the unseen spindle's forward
  // speed since the resolver froze: what the measured current can make less what the load and the
  // drive's friction take, over the reflected inertia (a rotor accelerating when the resolver froze
  // coasts on after its current is cut; UnpoweredHoldDetector).
  bool unpowered_coast_bound = true;
  int unpowered_settle_samples = 20;
  double unpowered_min_load_margin_kN = 0.5;
  double unpowered_kN = 0.5;

  // Noise: in a window of the residual's sample-to-sample changes, the share larger than
  // noise_step_kN (a single step, e.g. a bias or a resolver jump, is one sample, not noise).
  int noise_window_samples = 32;              // <= kMaxNoiseWindow
  double noise_step_kN = 0.25;                // about 6x the healthy change (0.03 kN RMS load cell)
  double noise_min_fraction = 0.25;
  // Once the resolver is diagnosed there is no residual (it needs the position): the load cell's
  // own second difference F[k] - 2F[k-1] + F[k-2] then counts as big beyond this (N(0, 2.45 x
  // the load cell's RMS): 0.4 % of a healthy 0.05 kN load cell's beyond 0.35 kN, 57 % of a
  // 0.25 kN RMS burst's; the clamp force's own second difference is below 0.03 kN per sample
  // even in 10 Hz ABS modulation).
  double noise_second_difference_kN = 0.35;
  // The corner's own healthy level: the mean |step| of the residual, learnt with this time
  // constant while the window is below a finding (noise_min_fraction), counted once a whole time
  // constant is learnt. A step then counts as big beyond max(noise_step_kN, noise_learned_factor x
  // that mean) (Gaussian: the mean |step| is
  // 0.8 sigma, so 4x is 3.2 sigma; for a 0.05 kN load cell it stays below 0.25 kN, for a 0.08 kN
  // one it is about 0.36 kN). 0: the fixed step only.
  double noise_learned_factor = 4.0;
  double noise_learn_time_constant_s = 1.0;
  // Without a residual (the resolver diagnosed), the load cell's own second differences teach
  // their level too; it counts after this much learning (a burst is found by the fixed
  // noise_second_difference_kN within a window, 32 ms, before it could be learnt; a healthy 0.08 kN
  // load cell crosses that threshold in 7 % of samples and was named noisy within 0.25 s).
  double noise_second_difference_learn_s = 0.1;
  // Below the trusted range (released: the residual is not judged there, the keys snap), the load
  // cell's own second differences as above (twenty-second session: tuning seed 1403 run 506, a
  // 0.55 kN RMS burst from 0.56 s while the pads were still off the disc, named only at 1.28 s
  // once the clamp force reached the trusted range). Counted only once their own level is learnt
  // (noise_second_difference_learn_s) or the residual's: the fixed threshold raised 9 fault-free
  // findings in the first 0.1 s on the stress population's noisier load cells (stress seed 1406).
  bool noise_released = true;
  // Each of the two paths (the residual's steps, the load cell's second differences) restarts
  // the other's learning clock when it takes over: the first value after the other path ran is
  // not weighed by the time the other path ran. Without it, the second differences' level after
  // 0.5 s of residual steps was one sample's |value| (weight 1): a healthy 0.08 kN load cell's
  // level learnt at 0.09 kN instead of 0.15 kN, and its second differences crossed the fixed
  // 0.35 kN in 8 of 32 samples (extreme hunt seed 2613 run 478, load_cell_noisy while released).
  bool noise_paths_restart_learning = true;

  // Dropout: consecutive samples without a load-cell value.
  int dropout_samples = 5;
  // A dropout ends: after this many consecutive samples with a value again the load-cell finding
  // (a dropout only) clears, and the calibrator it stopped resumes from the last good curve.
  int dropout_clear_samples = 200;
  // After a load-cell finding the corner's curve (its force feedback and the CCU's estimate) is
  // the newest fit before the fault's onset where that fit had data and, with an end-of-line
  // curve, that curve's rise beyond, refitted as one cubic from curve_min_rev to where the
  // end-of-line curve reaches force_limit_kN (bridge_curve). Off: the fit itself, extrapolated
  // (33.6 kN read at 7.7 rev on a soft caliper clamping 14.6; faster-driver campaign run 68).
  bool lost_load_cell_curve_from_eol = true;
  // With an end-of-line curve, the corner's calibrator starts from that caliper's own curve (a
  // cubic over the calibrator's range at the curve's reference temperature) instead of the
  // configured initial curve (the shipped caliper's end-of-line cubic). Its fits replace the
  // initial curve only where their cycles had data (calibrator_start in corner_supervisor.hpp).
  bool calibrator_initial_curve_from_eol = true;
  // With an end-of-line test that measured the drive's viscous friction (eol_viscous_kN_per_rev_
  // per_s > 0), the corner's calibrator fits its own viscous term (c_v v, CalibratorConfig::
  // viscous_friction). Without it, the fits took the viscous force of fast applies and releases
  // for key friction: 7.3-8.7 kN of friction on keys that hold 3.2-3.7 kN, the estimate 3.5-5.5 kN
  // off in holds (faster-driver campaign seed 3102 runs 27 and 267).
  bool calibrator_viscous_from_eol = true;
  // Likewise its keys' friction growth with the clamp force (eol_friction_load_gain > 0: the
  // calibrator's load_friction_gain and reference) and its play (eol_backlash_rev > 0: its
  // backlash_width_rev). Without them, a calibrator started from the end-of-line keys
  // (calibrator_friction_from_eol) left 1.4 kN of a load-dependent friction and 2.2 kN of keys
  // acting across the play in its estimate (stiff10_ff run 17, FR and RR).
  bool calibrator_load_friction_from_eol = true;
  bool calibrator_backlash_from_eol = true;
  // With an end-of-line curve, the calibrator's position constants are that caliper's, not the
  // shipped one's: its range [x_min, x_max] becomes the positions where the caliper's end-of-line
  // curve (at its reference temperature) clamps what the configured initial curve clamps at the
  // configured range's ends, and the cycle span a curve update needs (min_cycle_span_rev) and the
  // start detector's margin scale with that range. Only narrower ranges are taken (a cubic over a
  // soft caliper's wider one misses its exponential rise by 3 kN; beyond the configured range the
  // end-of-line curve carries a lost load cell's curve). Without it a caliper 3-10 x as stiff
  // modulated within one cycle span and was never fitted (stiff10 campaign).
  bool calibrator_range_from_eol = true;
  // With an end-of-line key-friction measurement, the calibrator's largest element threshold
  // (delta_max_rev) is the caliper's largest key threshold, when smaller than the configured one.
  // The element states count as known once the position has moved twice delta_max one way: with
  // the configured 0.8 rev, 68 of 100 corners of stiff calipers (travel 1.2-1.5 rev) never knew
  // them and so never fitted (stiff10 campaign, first 25 runs).
  bool calibrator_elements_from_eol = true;
  // With an end-of-line key-friction measurement, the calibrator starts from that caliper's key
  // friction: each measured element's force share K Delta on the calibrator's two nearest
  // thresholds (split in log spacing), as K_i measured like a fit's (Estimate::friction_fitted
  // once their states are known: the tracking rules count that friction), and its viscous
  // coefficient with its viscous term. Its fits refine them; before the first, the estimate is the
  // load cell less that friction instead of the load cell as it is (keys 0.3-4 kN wide in it; 11-16
  // of 100 corners of the stiff10 and soft10 campaigns and 14 of 79 of the tuning one never fit in
  // 16-24 s).
  bool calibrator_friction_from_eol = true;
  // ... and holds it as its friction memory's prior of this weight (Calibrator::set_friction_
  // prior: the information of that sum of n_i^2), so that cycles that cannot tell the keys from
  // the curve leave them as measured (0: the first fit replaces them whatever it could tell).
  double calibrator_friction_prior_weight = 50.0;
  // After a resolver finding the estimate is the load cell less the friction frozen at the
  // finding: the friction as it was before the fault's onset (the newest of the last
  // CornerSupervisor::kFrictionHistory samples older than it), not at the confirming sample. A
  // resolver offset's jump swings the calibrator's friction states before it is confirmed: frozen
  // there, -4.9 kN instead of +3.8 put the estimate 6.4 kN above the clamp force and named the
  // healthy actuator actuator_not_releasing (faster-driver campaign seed 3102 run 55).
  bool lost_resolver_friction_before_onset = true;
  // And the tracking rules count that friction as they count the calibrator's (the estimate is
  // the load cell less it): without, a caliper whose keys held its clamp force 2.7 kN below a
  // 10 kN command in a hold was named actuator_tracking once its resolver was named (run 55).
  bool lost_resolver_tracking_counts_friction = true;

  // Actuator torque balance: the torque the axial load and the acceleration need,
  // load * Nm_per_kN + J 2 pi a, against the torque the measured current should make,
  // i * torque_per_A; both low-pass filtered, their ratio is the delivered torque fraction.
  double torque_per_A_Nm = 0.27;              // at the spindle (scenario::actuator_model)
  double Nm_per_kN = 0.0398;
  double inertia_kg_m2 = 3.0e-3;              // reflected to the spindle
  double torque_filter_s = 0.01;
  double torque_check_min_load_kN = 8.0;      // drive friction is small against the load above this
  double torque_check_min_torque_Nm = 0.2;    // expected torque below this: no check
  double torque_fraction_threshold = 0.6;     // at standstill, below this: torque loss (kept in use)
  double torque_check_max_speed_rev_per_s = 0.5;
  // Applying (issue 14): at or above this speed the drive's Coulomb and viscous friction are
  // known in sign and size, and the balance need + friction against made holds in motion too, so
  // a torque loss is named during the apply instead of at the next hold (0: off).
  double torque_check_moving_min_speed_rev_per_s = 0.5;
  // ... and from this load on (the drive's friction is then known, not bounded: a load cell
  // reading b kN low gives the fraction 1 - b / (load + friction / Nm_per_kN), which stays above
  // torque_fraction_threshold for biases up to the largest the campaigns draw).
  double torque_check_moving_min_load_kN = 4.0;
  // From this load up to torque_check_moving_min_load_kN the torque-loss rule judges applying
  // too, and braking from here, both with the larger plausible load (the end-of-line curve's with
  // its band, where the position is known) so that a load cell reading low is not a weak motor
  // (twentieth session: a 66 % loss in a slow apply named at 4 kN, 1.035 s after it; tuning seed
  // 1403 run 72). 0: the moving checks from torque_check_moving_min_load_kN only.
  double torque_check_moving_low_load_kN = 2.0;
  double torque_persist_s = 0.04;
  double torque_lost_threshold = 0.25;        // at any speed, below this: the actuator is lost
  double torque_lost_persist_s = 0.015;
  // Once a torque loss is named, the drive is judged as the weaker drive it now is (issue 14,
  // thirteenth session): the lost rules may take the made torque scaled by the remaining fraction
  // estimated when the loss was named (the torque balance's fraction, or the actuator test's
  // answers against the corner's healthy one; within [torque_lost_threshold, 1]), and each takes
  // whichever of the two (scaled or not) makes it the less likely: so they name a further loss,
  // not the one already named (a 56 % loss named lost 4.3 s later while the motor crossed a
  // backlash gap: tune_b run 488), and nothing becomes more likely (scaled both ways, a positive
  // torque slowing a rotor that moved back looked like pulling: tune run 17).
  bool torque_loss_rescales_drive = true;
  // A load not measured (the load cell diagnosed: the force estimate is a curve) is taken at
  // the top of its plausible range (the end-of-line curve's with the key friction's width and
  // the curve's band) by the lost and torque-loss rules (fourteenth session: a healthy drive
  // decelerated against more load than an uncalibrated curve says looked as if its torque went
  // nowhere).
  bool torque_lost_unmeasured_load_high = true;
  // The lost rule also while the motor brakes the rotor at speed (its torque against the motion
  // at least torque_check_min_torque_Nm, at torque_check_moving_min_speed_rev_per_s or faster, the
  // load cell's load): the rotor's deceleration needs the load, the acceleration and the drive's
  // friction from the motor; a motor without torque leaves the load and the friction alone to
  // stop it (tuning seed 1403 run 158: a total loss at 25 rev/s in a hard stop's apply coasted the
  // caliper to 70 kN against -40 A and was never named).
  bool torque_lost_braking = true;
  // ... below this fraction: at speed the fraction leans on the drive's friction model and the
  // inertia term, and a 74 % loss read 0.2-0.26 there (scoring seed 1402 run 1751, named lost);
  // a motor without torque reads about 0.
  double torque_lost_braking_threshold = 0.15;
  // The torque-loss rule while the motor brakes the rotor at speed too (twentieth session): the
  // same balance as lost_braking's, from torque_check_moving_min_load_kN of the load cell's load
  // (from torque_check_moving_low_load_kN with the end-of-line curve, its larger plausible load
  // judged), below this fraction. A drive released slowly under load holds the screw back against the
  // load (less its friction); a weaker motor needs proportionally more current for it (tuning
  // seed 1406 run 112: a 59 % loss at 7 kN in a slow release, named only after it ended). 0: off.
  double torque_loss_braking_threshold = 0.6;
  // The torque rules go on after a resolver is named offset: its speed is still the rotor's (an
  // offset moves the position only), and its position, less the offset, while compensated
  // (resolver_jump.compensate). Tuning seed 1403 run 780: a total loss 0.1 s after a resolver
  // offset on the same corner, named only by the slower tracking rule, late.
  bool torque_after_resolver_offset = true;
  // Within this of the drive's retracted end stop (drive.retracted_stop_rev) a pull is not
  // unexplained: the stop takes it.
  double torque_stop_margin_rev = 0.02;
  // Unexplained torque (issue 14: a seized drive or a motor that makes no torque, at any load):
  // near standstill, the measured current's torque against what the load, the acceleration and
  // the drive's friction need. Pushing: make - need > drive.coulomb_friction_Nm + unexplained_margin_Nm
  // + unexplained_relative |need|. Pulling: need - make > the same + |need| (a gear in its
  // backlash gap carries none of the load the load cell reads). For unexplained_persist_s:
  // ActuatorLost.
  // Pulling, also: what the pull needs (the drive's friction against it and, on a caliper with
  // play, the load carried or not) is less than torque_lost_threshold of the pull, as pushing
  // (twenty-second session). A partial torque loss the loop absorbs pulls harder than a healthy
  // drive, not without answer (tuning seed 1401 run 341: a 72 % loss braking an apply at 2 kN
  // pulled 3.5 times its need and was named lost).
  bool unexplained_pull_fraction = true;
  plant::TransmissionParams drive;            // the drive's friction (the plant's transmission: plant::drive_friction_Nm)
  double unexplained_margin_Nm = 0.1;
  double unexplained_relative = 0.3;
  double unexplained_max_speed_rev_per_s = 2.0;
  double unexplained_persist_s = 0.03;
  // A seized drive in a hold: the position stays within seized_static_rev of where it stopped for
  // at least seized_window_s, the force stays within seized_force_error_kN of its command, and the
  // made torque has risen by seized_ramp_Nm since the drive stopped (the loop's integrators wind
  // up against a rotor that does not turn; a healthy or weakened drive turns, or needs no more
  // current while the force is where it is commanded). Such a ramp counts as a lost actuator once
  // the torque is unexplained (beyond the band above), and it is not named a torque loss.
  double seized_static_rev = 1.0e-4;
  double seized_window_s = 0.1;
  double seized_ramp_Nm = 0.3;
  double seized_force_error_kN = 0.5;
  // Off its command the same, once the made torque has risen by this much since the drive stopped
  // (twenty-second session): a healthy drive breaking away towards its command turns once the rise
  // passes the friction that can hold it (2 x (the drive's 0.05 Nm + the keys' half-width x
  // Nm_per_kN), 0.26 Nm at a 2 kN half-width); a seized one does not (tuning seed 1401 run 124: a
  // drive seized in a 24 kN hold, its force estimate 3 kN below the command after a stuck load
  // cell, wound its current from 3.5 to 40 A and was named a torque loss). 0: off.
  double seized_ramp_off_command_Nm = 1.0;
  // The corners' actuator test in holds (issue 14; corner_unit::ControllerParams::hold_test_*,
  // set from the scenario): the loops hold their current I, the command is I - a for test_pulse_s,
  // then I + a, a = |I| + test_pulse_current_A. Recognised in the measured current (it fell by at
  // least half the test current into the - half; the halves' means of opposite signs, each at
  // least half the test current off 0 and 1.3 test currents apart; every + sample 0.8 of it above
  // every - one), from a rotor at most test_pulse_max_speed_rev_per_s fast: the rotor's speed
  // over it (the fall over the - half less the fall over the + half) against a free rotor's under
  // that current. Below test_pulse_answer_ratio: not answered; test_pulse_unanswered such or more
  // in a row, each within test_pulse_within_s of the last judged pulse, whose answers' mean is
  // below test_pulse_lost_mean_ratio: ActuatorLost (a seized drive or a motor that makes no
  // torque answers with its speed noise about 0; a partial loss weakly). 0 A: no test.
  // test_pulse_s at most 7 sample periods.
  // Weak answers (issue 14, thirteenth session): the mean of the last test_pulse_weak_count
  // answers below test_pulse_weak_fraction of the corner's healthy answer, while the mean of the
  // latest half of them is at least test_pulse_answer_ratio: ActuatorTorqueLoss (the answer
  // scales with the torque the motor makes); that latest half's mean below
  // test_pulse_lost_mean_ratio: ActuatorLost (a dead drive's noise, which may answer now and
  // then at high loads). The healthy answer is learnt per corner,
  // the mean of the answers that left that window, once test_pulse_learn_count are in; until then
  // the drive's nominal test_pulse_healthy_ratio. test_pulse_weak_count 0: no such rule.
  double test_pulse_current_A = 0.0;
  double test_pulse_s = 0.003;
  double test_pulse_max_speed_rev_per_s = 0.2;
  double test_pulse_answer_ratio = 0.15;
  int test_pulse_unanswered = 2;
  double test_pulse_lost_mean_ratio = 0.075;
  // A test is recognised when each half's extreme sample crosses 0 by half the test current (the
  // halves' means before: missed every test from a hold current of about 6.5 A, the current's lag).
  bool test_pulse_crossing_extremes = true;
  // After a named torque loss (torque_loss_rescales_drive) the tests' answers are judged against
  // the motor that is left: the answer divided by the remaining fraction estimated then.
  bool test_pulse_rescaled_after_loss = true;
  double test_pulse_within_s = 0.04;          // each unanswered pulse within this of the last judged one
  int test_pulse_weak_count = 8;              // at most TorqueDetector::kMaxWeakCount
  double test_pulse_weak_fraction = 0.65;
  double test_pulse_healthy_ratio = 0.69;
  int test_pulse_learn_count = 16;
  // Tracking backstop: the force against a first-order model of the commanded response. A
  // shortfall below both is ActuatorTracking; an excess above both (a brake that does not
  // release) is ActuatorNotReleasing, with the same threshold and persistence.
  double tracking_time_constant_s = 0.1;
  double tracking_threshold_kN = 3.0;
  double tracking_relative = 0.3;             // of the command
  double tracking_persist_s = 0.2;
  // A drive running towards its command at tracking_full_speed_fraction of its speed limit
  // (drive_max_speed_rev_per_s, the corners' controller.max_speed_rev_per_s) does all it can:
  // the model is held at the force estimate then (a command response cannot outrun the drive).
  // Without it a corner that re-applied a 37 kN hard stop from its released safe state after a
  // 0.72 s link silence, 0.28 s at the 25 rev/s limit, was named actuator_tracking (tune_b seed
  // 1403 run 752). 0: off.
  double tracking_full_speed_fraction = 0.8;
  double drive_max_speed_rev_per_s = 0.0;     // 0: unknown (the rule above off)
  double force_limit_kN = 40.0;               // commands above it are not expected to be reached
  // An excess is a brake that does not release only while it does not move back at least this
  // fast (a brake that releases, if slowly, e.g. back-driven after a torque loss, moves).
  double release_min_speed_rev_per_s = 0.5;
  // With an end-of-line curve and a resolver judged right, the excess counts a clamp force no
  // higher than the curve allows where the keys can be furthest in (the measured position plus
  // half the play; + end_of_line.relative and band, + its speed term): a load cell reading more
  // than that is the keys' friction or its offset (a load-cell matter), not a brake holding force.
  // A caliper at rest at its released position with 3.6 kN of friction stuck in its keys and a
  // hot load cell's 0.65 kN read 4.2 kN against a zero command (extreme hunt run 193).
  bool tracking_excess_position_bound = true;
  // The shortfall, likewise, counts no less clamp force than 0 (the pads push, never pull) and,
  // with an end-of-line curve and a resolver judged right, than the curve allows where the keys
  // can be furthest out (the position less half the play; less relative, band and speed): a load
  // cell reading less is the keys' friction pulling it (a caliper whose 3.9 kN keys read -3.9 kN
  // at rest after a hard stop's release against a zero command, extreme hunt seed 2614 run 262).
  bool tracking_shortfall_position_bound = true;
  // The calibrator's friction counts (see TrackingDetector) once its friction term is fitted
  // where the keys are (calibration::Estimate::friction_fitted): after a restart (a corner back
  // from a lost link or a cleared sensor finding) that is as soon as the snapshot's K_i it
  // restarted with have their states again, not only after its first fit of its own. Off: only
  // after that fit; until then the keys' friction, 3-4 kN on the extreme population, counted
  // as a brake holding force (faster-driver campaign seed 3102 runs 27, 61, 101, 377: a healthy
  // corner named actuator_not_releasing in a slow release after the corner came back).
  bool tracking_friction_after_restart = true;
  // The tracking rules count the friction the calibrator's estimate took out of the load cell
  // whenever it took some, also while its element states are not known yet (a calibrator that
  // starts from the caliper's end-of-line key friction, calibrator_friction_from_eol, takes it
  // out from the first sample). Off: only where it is fitted (above); until then the estimate
  // without the keys counted as the brake's whole force: a healthy corner whose load-cell loop
  // stood on 3.6-3.8 kN of keys before the pads touched was named actuator_tracking (stiff10_ff
  // campaign run 17, soft10_ff run 2).
  bool tracking_friction_as_subtracted = true;

  // Link: no sample for this long is a lost link (the DDS deadline in the process).
  double deadline_s = 0.015;

  void validate() const;  // throws std::invalid_argument naming the field, value and rule
};
// A corner's guard limits: MonitorParams::guard, its position range widened by
// guard_position_from_eol.
GuardLimits guard_for_corner(const MonitorParams& p);

class FaultMonitor {
 public:
  FaultMonitor(const MonitorParams& params, Target corner);  // throws std::invalid_argument

  // One sample. `check` is the guard's verdict on it; `estimate` is the calibrator's output for
  // it when the calibrator was fed (nullptr otherwise); `force_estimate_kN` is the clamp force
  // the CCU currently believes (NaN when it has none); arrival_s is when the CCU got it.
  // `load_cell_friction_kN`: when force_estimate_kN is the load cell less a friction that is not
  // the calibrator's (after a resolver finding, the frozen one), that friction; NaN otherwise.
  void update(const CornerReading& r, const SampleCheck& check, const calibration::Estimate* estimate,
              double force_estimate_kN, double arrival_s,
              double load_cell_friction_kN = std::numeric_limits<double>::quiet_NaN());
  void on_link_event(LinkEvent e, double time_s) { link_.on_link_event(e, time_s, arbiter_); }
  // Deadline check at the CCU's time now_s.
  void tick(double now_s) { link_.tick(now_s, p_, arbiter_); }

  const Diagnosis& diagnosis(Part p) const { return arbiter_.diagnosis(p); }
  bool ok(Part p) const { return arbiter_.ok(p); }
  // A stuck resolver leaves the motor without commutation (the corner's controller drives no
  // current, corner_unit::ControllerParams::frozen_resolver_samples): the corner holds what it has.
  bool commutation_lost() const {
    const Diagnosis& d = arbiter_.diagnosis(Part::Resolver);
    return d.active && d.finding == Finding::ResolverStuck;
  }
  // Samples arrived again after a link or process loss; cleared by take_rejoin().
  bool rejoined() const { return link_.rejoined(); }
  bool take_rejoin() { return link_.take_rejoin(); }
  // Whether a usable sample comes after an unseen gap (MonitorParams::residual_unseen_gap_forgets:
  // more than jump_max_gap_s since the last usable one, within one incarnation): where the
  // position went meanwhile is unknown, so is the keys' state. Asked before update() with it.
  bool unseen_gap_before(const CornerReading& r) const {
    return p_.residual_unseen_gap_forgets && have_prev_ && r.time_s - prev_.time_s > p_.jump_max_gap_s;
  }
  // A dropout finding cleared (its values are back); true once per clearing.
  bool take_load_cell_cleared() { return dropout_.take_cleared(); }
  // A stuck-resolver finding cleared (the resolver lives again); true once per clearing.
  bool take_resolver_cleared() { return stuck_.take_resolver_cleared(); }
  // Whether the last loss was the process (liveliness), so its sequence starts again.
  bool process_was_lost() const { return link_.process_was_lost(); }
  // Delivered / expected torque, from the last torque check (1 until one ran).
  double torque_fraction() const { return torque_.fraction(); }
  // Narrows the calibrated residual check to where the calibrator's fits had data (the
  // end-of-line band covers the rest), and scales its thresholds with the fit's residual RMS.
  void set_curve_range(double min_rev, double max_rev);
  void set_fit_rms(double fit_rms_kN) { residual_.set_fit_rms(fit_rms_kN); }
  // At an accepted fit: its friction amplitude (the most friction it can give, kN). Beyond
  // eol_friction_amplitude_factor x the key-friction half-width the fit is not credible and the
  // residual uses the end-of-line band until a credible one.
  void set_fit_friction_amplitude(double amplitude_kN) {
    const double hw = p_.eol_friction_half_width_kN, f = p_.eol_friction_amplitude_factor;
    residual_.set_fit_credible(!p_.eol_curve || (amplitude_kN <= f * hw && amplitude_kN >= hw / f));
  }
  // Whether the last accepted fit was credible (true before any).
  bool fit_credible() const { return residual_.fit_credible(); }
  // The last residual inside the curve's range (NaN outside it or before the first).
  double last_residual_kN() const { return residual_.residual_kN(); }
  // The last residual minus its reference level (NaN where the residual is).
  double last_residual_change_kN() const { return residual_.change_kN(); }
  // The thresholds the last residual and its change were held against (NaN where none applied).
  double last_residual_threshold_kN() const { return residual_.threshold_kN(); }
  double last_residual_change_threshold_kN() const { return residual_.change_threshold_kN(); }
  // The hold rule's change since its hold settled and its allowance (kN; NaN outside a hold).
  double last_hold_change_kN() const { return residual_.hold_change_kN(); }
  double last_hold_threshold_kN() const { return residual_.hold_threshold_kN(); }
  double last_revisit_change_kN() const { return residual_.revisit_change_kN(); }
  double last_revisit_threshold_kN() const { return residual_.revisit_threshold_kN(); }
  double last_modulation_kN() const { return residual_.modulation_kN(); }
  double last_modulation_threshold_kN() const { return residual_.modulation_threshold_kN(); }
  // A residual disagreement is under way but not yet confirmed: the calibrator must not learn
  // from these samples (CornerSupervisor holds its fits).
  bool residual_suspect() const { return residual_.suspect(); }
  // The unpowered-hold rule's bound on the spindle's forward speed (rev/s; the measured speed while
  // the resolver lives, what the current could add since it froze).
  double unpowered_forward_speed_bound_rev_per_s() const { return unpowered_.forward_speed_bound_rev_per_s(); }
  // Share of large residual steps in the noise window.
  double last_noise_fraction() const { return noise_.fraction(); }
  Target corner() const { return corner_; }
  const MonitorParams& params() const { return p_; }

 private:
  MonitorParams p_;
  Target corner_;
  DiagnosisArbiter arbiter_;
  DropoutDetector dropout_;
  JumpDetector jump_;
  StuckDetector stuck_;
  NoiseDetector noise_;
  ResidualDetector residual_;
  TorqueDetector torque_;
  StepDetector step_;
  MovingStepDetector moving_step_;
  UnpoweredHoldDetector unpowered_;
  TrackingDetector tracking_;
  LinkDetector link_;
  // The previous usable sample (continuity for the detectors; broken by a rejoin).
  bool have_prev_ = false;
  int compensated_jumps_ = 0;  // the resolver's confirmed jumps the compensated residual started from
  CornerReading prev_{};
  bool prev_lc_present_ = false;
};

}  // namespace bbw::faults
