#include "bbw/faults/detectors/torque_detector.hpp"

#include <algorithm>
#include <cmath>

#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

TorqueDetector::TorqueDetector(const MonitorParams& p) {
  if (p.eol_curve) eol_.emplace(*p.eol_curve);
}

void TorqueDetector::update(const SampleContext& c, double load_kN, bool load_cell_load, bool position_known,
                            const MonitorParams& p, DiagnosisArbiter& a) {
  const CornerReading& r = c.r;
  const double t = r.time_s;
  pulse_samples_ = 0;
  // Samples lost between two usable ones (no rejoin: a corner in an outage whose blocks came
  // through one or two at a time) break the filters, the acceleration and every persistence: they
  // start again. Otherwise a suspicion from one block was confirmed by the first sample of the
  // next, 0.28 s later (realtime SystemNetns.CornerLinkDownIsDetectedAndTheCornerRejoins: a
  // healthy corner named lost as its link came back).
  if (c.have_prev && c.dt_s > p.jump_max_gap_s) on_rejoin();
  const bool continuous = c.have_prev && c.dt_s > 0.0 && c.dt_s <= p.jump_max_gap_s;
  const double accel = continuous ? (r.speed_rev_per_s - c.prev.speed_rev_per_s) / c.dt_s : 0.0;
  // A frozen resolver repeats its last (noisy, so nonzero) speed exactly.
  const bool repeated = c.have_prev && r.speed_rev_per_s != 0.0 && r.speed_rev_per_s == c.prev.speed_rev_per_s;
  speed_repeats_ = repeated ? speed_repeats_ + 1 : 0;
  const Diagnosis& resolver = a.diagnosis(Part::Resolver);
  const bool speed_known = a.ok(Part::Resolver) || (p.torque_after_resolver_offset && resolver.active &&
                                                    resolver.finding == Finding::ResolverOffset);
  if (!speed_known || !std::isfinite(load_kN) || speed_repeats_ >= p.frozen_attribution_samples) {
    torque_init_ = torque_suspect_ = lost_suspect_ = unexplained_init_ = unexplained_suspect_ = static_init_ = false;
    reset_response();
    return;
  }
  update_response(c, p, a);
  constexpr double kTwoPi = 6.283185307179586;
  const double need = load_kN * p.Nm_per_kN + p.inertia_kg_m2 * kTwoPi * accel;
  const double make = r.motor_current_A * p.torque_per_A_Nm;
  const double drive_friction = plant::drive_friction_Nm(p.drive, r.speed_rev_per_s);
  if (!torque_init_ || c.dt_s <= 0.0) {
    torque_init_ = true;
    torque_since_s_ = r.time_s;
    need_Nm_ = need;
    make_Nm_ = make;
    friction_Nm_ = drive_friction;
  } else {
    const double k = -std::expm1(-c.dt_s / p.torque_filter_s);
    need_Nm_ += (need - need_Nm_) * k;
    make_Nm_ += (make - make_Nm_) * k;
    friction_Nm_ += (drive_friction - friction_Nm_) * k;
  }
  // Applying at speed the drive's friction opposes the motion with a known size, so it joins the
  // need; at standstill it can take any value within its band and is left out (the load is large
  // against it above the check's minimum load). Only with the load cell's load: the force
  // estimate is the clamp force, without the key friction the drive pushes against in motion.
  const bool applying = load_cell_load && p.torque_check_moving_min_speed_rev_per_s > 0.0 &&
                        r.speed_rev_per_s >= p.torque_check_moving_min_speed_rev_per_s;
  const bool checkable = load_kN >= (applying ? p.torque_check_moving_min_load_kN : p.torque_check_min_load_kN) &&
                         make_Nm_ >= p.torque_check_min_torque_Nm;
  const double fraction = !checkable ? 1.0 : applying ? (need_Nm_ + friction_Nm_) / make_Nm_ : need_Nm_ / make_Nm_;
  if (checkable) fraction_ = fraction;
  // The load's plausible range (below): with the end-of-line curve, also the curve's at the
  // measured position and temperature with the key friction's width and the curve's band.
  const double accel_Nm = p.inertia_kg_m2 * kTwoPi * accel;
  double load_hi_kN = load_kN, load_lo_kN = load_kN;
  if (eol_ && position_known) {
    const double temperature_C = std::isfinite(r.temperature_C) ? r.temperature_C : eol_->params().reference_temperature_C;
    const double eol_kN = eol_->force_kN(r.position_rev, temperature_C, 0.0);
    const double band_kN = p.eol_friction_half_width_kN + p.eol_band_kN + p.eol_relative * std::abs(eol_kN);
    load_hi_kN = std::max(load_kN, eol_kN + band_kN);
    load_lo_kN = std::min(load_kN, eol_kN - band_kN);
  }
  const double hi = load_hi_kN * p.Nm_per_kN + accel_Nm, lo = load_lo_kN * p.Nm_per_kN + accel_Nm;
  if (!unexplained_init_ || c.dt_s <= 0.0) {
    unexplained_init_ = true;
    need_hi_Nm_ = hi;
    need_lo_Nm_ = lo;
  } else {
    const double k = -std::expm1(-c.dt_s / p.torque_filter_s);
    need_hi_Nm_ += (hi - need_hi_Nm_) * k;
    need_lo_Nm_ += (lo - need_lo_Nm_) * k;
  }
  // Lost: against the drive as it now is (after a named torque loss, its remaining torque). For
  // this rule and the torque loss's (below), a load not measured (the load cell diagnosed: the
  // force estimate is a curve, up to a quarter off an uncalibrated caliper's) is taken at the top
  // of its plausible range: a drive decelerated against more load than the estimate says looked
  // as if its torque went nowhere (tuning seed 1403 run 502: estimate 8.4 kN, true 11.0 kN and
  // 2.0 kN of key friction; lost at 20.9 s).
  const double judged_fraction =
      !checkable || load_cell_load || !p.torque_lost_unmeasured_load_high ? fraction : std::max(fraction, need_hi_Nm_ / make_Nm_);
  // Braking at speed (the made torque against the motion): a healthy drive's made torque is the
  // need plus the friction against the motion, whatever their signs. On a caliper with play the
  // motor crosses the gap carrying none of the load (the spindle's own friction holds it: tuning
  // seed 1401 run 57, a healthy corner backing off at 29 kN): the lost verdict takes whichever of
  // the two needs, with the load or without, makes the drive the less lost.
  const bool braking_at_speed = load_cell_load && p.torque_check_moving_min_speed_rev_per_s > 0.0 &&
                                std::abs(make_Nm_) >= p.torque_check_min_torque_Nm && make_Nm_ * r.speed_rev_per_s < 0.0 &&
                                std::abs(r.speed_rev_per_s) >= p.torque_check_moving_min_speed_rev_per_s;
  const bool braking = braking_at_speed && p.torque_lost_braking;
  const double carried_Nm = p.eol_backlash_rev > 0.0 ? std::max(0.0, load_kN) * p.Nm_per_kN : 0.0;
  // The torque-loss verdict braking, and applying below the moving check's load, takes the larger
  // plausible load (the end-of-line curve's with its band, when the position is known): at a low
  // load, and braking (the need less the friction), a load cell that reads low looks like a weak
  // motor (computed: a load cell 2 kN low reads 0.57 while the motor holds back a release at 6 kN).
  const bool plausible = eol_.has_value() && position_known;
  const double need_judged_Nm = plausible ? std::max(need_Nm_, need_hi_Nm_) : need_Nm_;
  const double braking_fraction =
      !braking_at_speed ? 1.0
                        : std::max((need_Nm_ + friction_Nm_) / make_Nm_, (need_Nm_ - carried_Nm + friction_Nm_) / make_Nm_);
  const double braking_judged_fraction =
      !braking_at_speed ? 1.0 : std::max(braking_fraction, (need_judged_Nm + friction_Nm_) / make_Nm_);
  // The moving checks' least load: from torque_check_moving_low_load_kN where the curve gives the larger load.
  const bool low_load = plausible && p.torque_check_moving_low_load_kN > 0.0;
  const double moving_min_load_kN = low_load ? p.torque_check_moving_low_load_kN : p.torque_check_moving_min_load_kN;
  const bool applying_low = applying && low_load && load_kN >= moving_min_load_kN &&
                            load_kN < p.torque_check_moving_min_load_kN && make_Nm_ >= p.torque_check_min_torque_Nm;
  const double applying_low_fraction = applying_low ? (need_judged_Nm + friction_Nm_) / make_Nm_ : 1.0;
  const bool lost_braking = braking && braking_fraction / motor_scale_ < p.torque_lost_braking_threshold;
  // The lost verdicts only once the filters have settled (kSettledTimeConstants of
  // torque_filter_s since they started): at a rejoin the acceleration is unknown, the need starts
  // at the load alone and lags the drive's motion (realtime system test
  // SystemNetns.CornerLinkDownIsDetectedAndTheCornerRejoins: a healthy corner backing off at
  // -4 rev/s in the outage's own release, seen as its link returned, was named lost 7 ms after
  // the filters started).
  const bool settled = r.time_s - torque_since_s_ >= kSettledTimeConstants * p.torque_filter_s;
  // Applying below the moving check's load, judged with the larger plausible load, the lost
  // threshold holds as above it: a drive with a fifth of its torque left, accelerating at its
  // current limit into a hard stop, is lost, not a torque loss kept in use (tuning seed 1403 run
  // 374: a 79 % loss named a torque loss, then not tracking 12 s later).
  const bool lost_applying_low = applying_low && applying_low_fraction / motor_scale_ < p.torque_lost_threshold;
  if (settled && ((checkable && judged_fraction / motor_scale_ < p.torque_lost_threshold) || lost_applying_low || lost_braking)) {
    if (!lost_suspect_) {
      lost_suspect_ = true;
      lost_onset_s_ = t;
    }
    if (t - lost_onset_s_ >= p.torque_lost_persist_s) a.confirm(Finding::ActuatorLost, lost_onset_s_, t);
  } else {
    lost_suspect_ = false;
  }
  // Unexplained torque near standstill, at any load: the current pushes (or pulls) beyond what
  // the load, the acceleration and the drive's friction take, and nothing moves (a seized
  // drive) or the motor's torque goes nowhere (no torque: the load back-drives the screw). The
  // load is the load cell's and, with an end-of-line curve, also the curve's (above): pushing,
  // the larger of the two must not explain the torque; pulling, the smaller (a load-cell fault
  // moves only one of them).
  const double load_Nm = std::max(std::abs(load_hi_kN), std::abs(load_lo_kN)) * p.Nm_per_kN;
  const double band = p.drive.coulomb_friction_Nm + p.unexplained_margin_Nm + p.unexplained_relative * load_Nm;
  excess_Nm_ = make_Nm_ - need_hi_Nm_;
  const bool slow = std::abs(r.speed_rev_per_s) <= p.unexplained_max_speed_rev_per_s;
  // Seized in a hold: stopped where it is, the force where it is commanded, and still the made
  // torque rises (MonitorParams::seized_*).
  const bool stopped = slow && static_init_ && std::abs(r.position_rev - static_position_rev_) <= p.seized_static_rev;
  if (!stopped) {
    static_init_ = true;
    static_position_rev_ = r.position_rev;
    static_since_s_ = t;
    static_min_make_Nm_ = make_Nm_;
  } else {
    static_min_make_Nm_ = std::min(static_min_make_Nm_, make_Nm_);
  }
  const bool on_command =
      std::isfinite(r.force_command_kN) && std::abs(r.force_command_kN - load_kN) <= p.seized_force_error_kN;
  // The loop winds up against a rotor that does not turn. (Not down: a healthy hold's current
  // may fall to about 0 A while the drive's and the keys' friction hold the load; tried on the
  // tuning seed, 3 fault-free false alarms in hard stops.)
  // Off the command, by more than any friction can hold a healthy drive back (breaking away).
  const double ramp_Nm = make_Nm_ - static_min_make_Nm_;
  const bool winding_up = stopped && t - static_since_s_ >= p.seized_window_s &&
                          (on_command ? ramp_Nm >= p.seized_ramp_Nm
                                      : p.seized_ramp_off_command_Nm > 0.0 && ramp_Nm >= p.seized_ramp_off_command_Nm);
  // Pushing: beyond the band and less than the lost threshold of it needed (a partial torque
  // loss the loop absorbs is not a lost actuator), or winding up against a seized drive.
  // (After a named torque loss the motor makes motor_scale_ of it, either way: each rule takes the
  // one of the two made torques that makes it the less likely, so only a further loss is named.)
  const double weak_Nm = make_Nm_ * motor_scale_;
  const double push_Nm = std::min(make_Nm_, weak_Nm), pull_Nm = std::max(make_Nm_, weak_Nm);
  const bool pushing = push_Nm - need_hi_Nm_ > band &&
                       (need_hi_Nm_ + p.drive.coulomb_friction_Nm < p.torque_lost_threshold * push_Nm || winding_up);
  // Pulling: beyond the band plus the whole load (a gear in its backlash gap carries none of it).
  // Not against the retracted end stop (the drive's, plant::TransmissionParams::retracted_stop_rev),
  // which takes any pull: a healthy drive released onto it by its loop pulls with up to its
  // current limit and does not move (tuning seed 1401 run 301, a loop releasing after a drifting
  // load cell).
  const bool at_stop = r.position_rev <= p.drive.retracted_stop_rev + p.torque_stop_margin_rev;
  // And, as pushing, with less than the lost threshold of the pull needed, the drive's friction
  // against it and, on a caliper with play, the load carried or not (in the gap the need is the
  // acceleration's alone): a partial loss the loop absorbs pulls harder, not in vain
  // (MonitorParams::unexplained_pull_fraction).
  const double gap_Nm = p.eol_backlash_rev > 0.0 ? load_Nm : 0.0;
  const bool pull_in_vain = !p.unexplained_pull_fraction ||
                            need_lo_Nm_ - gap_Nm - p.drive.coulomb_friction_Nm > p.torque_lost_threshold * pull_Nm;
  const bool pulling = !at_stop && need_lo_Nm_ - pull_Nm > band + load_Nm && pull_in_vain;
  if (slow && (pushing || pulling)) {
    if (!unexplained_suspect_) {
      unexplained_suspect_ = true;
      unexplained_onset_s_ = t;
    }
    if (t - unexplained_onset_s_ >= p.unexplained_persist_s) a.confirm(Finding::ActuatorLost, unexplained_onset_s_, t);
  } else {
    unexplained_suspect_ = false;
  }
  const bool still = std::abs(r.speed_rev_per_s) <= p.torque_check_max_speed_rev_per_s;
  const bool weak_still_or_applying = checkable && (still || applying) && judged_fraction < p.torque_fraction_threshold;
  const bool weak_braking =
      braking_at_speed && load_kN >= moving_min_load_kN && braking_judged_fraction < p.torque_loss_braking_threshold;
  const bool weak_applying_low = applying_low && applying_low_fraction < p.torque_fraction_threshold;
  if ((weak_still_or_applying || weak_braking || weak_applying_low) && !winding_up) {
    if (!torque_suspect_) {
      torque_suspect_ = true;
      torque_onset_s_ = t;
    }
    // Not while a lost verdict is pending (lost_persist_s): a drive whose torque fraction is below
    // the lost threshold is lost, and a torque loss named first would keep it in use (the lost
    // rules then judge the drive that is left: tuning seed 1403 run 374, a 79 % loss).
    if (t - torque_onset_s_ >= p.torque_persist_s && !lost_suspect_) {
      a.confirm(Finding::ActuatorTorqueLoss, torque_onset_s_, t);
      rescale_after_torque_loss(weak_still_or_applying ? judged_fraction
                                : weak_braking          ? braking_judged_fraction
                                                        : applying_low_fraction,
                                p, a);
    }
  } else {
    torque_suspect_ = false;
  }
}

void TorqueDetector::update_response(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a) {
  if (!(p.test_pulse_current_A > 0.0)) return;
  const CornerReading& r = c.r;
  // Consecutive samples evenly spaced (a gap, a late or a lost sample: the history starts again).
  const bool even = c.have_prev && c.dt_s > 0.0 && (response_count_ == 0 || std::abs(c.dt_s - response_dt_s_) <= 0.25 * response_dt_s_);
  if (!even || !std::isfinite(r.motor_current_A) || !std::isfinite(r.speed_rev_per_s)) response_count_ = 0;
  if (c.dt_s > 0.0) response_dt_s_ = c.dt_s;
  const int size = kHistory;
  response_head_ = (response_head_ + 1) % size;
  response_speed_[static_cast<std::size_t>(response_head_)] = r.speed_rev_per_s;
  response_current_[static_cast<std::size_t>(response_head_)] = r.motor_current_A;
  response_count_ = std::min(response_count_ + 1, size);
  const double dt_s = c.dt_s > 0.0 ? c.dt_s : 0.001;
  const int m = std::max(1, static_cast<int>(std::lround(p.test_pulse_s / dt_s)));
  if (2 * m + 2 > response_count_ || 2 * m + 2 > size) return;
  const auto at = [&](int back) { return static_cast<std::size_t>((response_head_ - back + size) % size); };
  const double amp_A = p.test_pulse_current_A;
  // A pulse whose - half (back) ran over the samples 2m .. m+1 back and its + half (forth) over
  // m .. 1 back: it fell into its first sample by at least half the test current, the halves'
  // means are at least 1.3 test currents apart (at least 2, less the current's lag) and every +
  // sample stands 0.8 of it above every - one (a hold's own current jitters by a few tenths of an
  // A from sample to sample, the pulse rides on the loop's current of the sample before it).
  double plus_A = 0.0, minus_A = 0.0, plus_min_A = 1e300, minus_max_A = -1e300, plus_max_A = -1e300, minus_min_A = 1e300;
  for (int k = 1; k <= m; ++k) {
    const double down = response_current_[at(m + k)], up = response_current_[at(k)];
    plus_A += up / m;
    minus_A += down / m;
    plus_min_A = std::min(plus_min_A, up);
    minus_max_A = std::max(minus_max_A, down);
    plus_max_A = std::max(plus_max_A, up);
    minus_min_A = std::min(minus_min_A, down);
  }
  const bool fell = response_current_[at(2 * m)] - response_current_[at(2 * m + 1)] <= -0.5 * amp_A;
  // ... and the current changes sign both ways, as the test's does (a = |I| + the test current),
  // and a hold's own current changing within a few milliseconds hardly ever does. With
  // test_pulse_crossing_extremes each half's extreme sample must cross, not its mean: from a hold
  // current above about 6.5 A the current (L/R 0.67 ms) is still positive at the - half's first
  // sample and the mean did not cross (tuning seed 1403 run 360: a drive seized at 35 kN wound
  // its current up to 10-17 A and none of its tests was judged).
  const bool crosses = p.test_pulse_crossing_extremes
                           ? minus_min_A <= -0.5 * amp_A && plus_max_A >= 0.5 * amp_A
                           : minus_A <= -0.5 * amp_A && plus_A >= 0.5 * amp_A;
  const bool square =
      fell && crosses && plus_A - minus_A >= 1.3 * amp_A && plus_min_A - minus_max_A >= 0.8 * amp_A;
  const double v0 = response_speed_[at(2 * m + 1)];
  if (square) pulse_samples_ = 2 * m;
  if (!square || std::abs(v0) > p.test_pulse_max_speed_rev_per_s) return;
  // Against the retracted end stop the stop takes the - half: no answer to judge (stress seed
  // 1406 run 362, a healthy drive released onto it by a loop on a noisy load cell).
  if (r.position_rev <= p.drive.retracted_stop_rev + p.torque_stop_margin_rev) return;
  constexpr double kTwoPi = 6.283185307179586;
  // A free rotor's answer to the measured swing: each half's current is half the swing off the
  // middle, so each half accelerates by that much torque.
  const double accel = 0.5 * (plus_A - minus_A) * p.torque_per_A_Nm / (kTwoPi * p.inertia_kg_m2);
  // The speed's fall over the - half less its fall over the + half (each from the speed before
  // the half): an acceleration the rotor had anyway (the load against the held current) cancels.
  const double vm = response_speed_[at(m + 1)];
  double measured = 0.0;
  for (int k = 1; k <= m; ++k) measured += (v0 - response_speed_[at(m + k)]) - (vm - response_speed_[at(k)]);
  const double free_rotor = 2.0 * accel * dt_s * m * (m + 1) / 2.0;
  // After a named torque loss the answer is judged against the motor that is left
  // (torque.loss_rescales_drive): a 62 % loss answers about 0.26 with the noise of a whole
  // drive's answer, two in a row below the lost mean now and then (tuning seed 1401 run 334: -0.05
  // and 0.13 in a hold at 10.5 kN, named lost); a further loss still answers about 0.
  const double ratio = measured / free_rotor / (p.test_pulse_rescaled_after_loss ? motor_scale_ : 1.0);
  // Unanswered pulses count in a row only while each follows the last judged one within
  // test_pulse_within_s (a test every hold_test_period_s while the hold lasts).
  if (unanswered_ > 0 && r.time_s - last_pulse_s_ > p.test_pulse_within_s) unanswered_ = 0;
  last_pulse_s_ = r.time_s;
  const double pulse_start_s = r.time_s - (2 * m + 1) * dt_s;
  if (ratio < p.test_pulse_answer_ratio) {
    if (unanswered_ == 0) {
      unanswered_since_s_ = pulse_start_s;
      unanswered_sum_ = 0.0;
    }
    ++unanswered_;
    unanswered_sum_ += ratio;
    // A dead drive answers with its speed noise about 0; a partial loss, weakly (below).
    if (unanswered_ >= p.test_pulse_unanswered && unanswered_sum_ / unanswered_ < p.test_pulse_lost_mean_ratio) {
      a.confirm(Finding::ActuatorLost, unanswered_since_s_, r.time_s);
    }
  } else {
    unanswered_ = 0;
  }
  judge_answers(ratio, pulse_start_s, r.time_s, p, a);
}

void TorqueDetector::judge_answers(double ratio, double pulse_start_s, double now_s, const MonitorParams& p,
                                   DiagnosisArbiter& a) {
  const int n = p.test_pulse_weak_count;
  if (n <= 0) return;
  // The answer that leaves the window is learnt: a fault is judged within n answers of its
  // onset, before its own answers could teach the reference.
  if (answers_count_ == n) {
    learnt_sum_ += answers_[static_cast<std::size_t>(answers_head_)];
    ++learnt_count_;
  }
  answers_[static_cast<std::size_t>(answers_head_)] = ratio;
  answers_start_s_[static_cast<std::size_t>(answers_head_)] = pulse_start_s;
  answers_head_ = (answers_head_ + 1) % n;
  answers_count_ = std::min(answers_count_ + 1, n);
  if (answers_count_ < n) return;
  const auto back = [&](int k) { return static_cast<std::size_t>((answers_head_ - k + n) % n); };
  double sum = 0.0, recent = 0.0;
  const int half = std::max(1, n / 2);
  for (int k = 1; k <= n; ++k) sum += answers_[back(k)];
  for (int k = 1; k <= half; ++k) recent += answers_[back(k)];
  recent /= half;
  // A dead drive answers with its speed noise about 0, which at high loads spreads to +-0.17:
  // two unanswered pulses in a row may be a while coming (tuning seed 1401 run 280, a drive
  // seized at 37 kN: -0.08, 0.16, -0.07, 0.15, -0.17). The recent half's mean is a dead drive's.
  if (recent < p.test_pulse_lost_mean_ratio) {
    a.confirm(Finding::ActuatorLost, answers_start_s_[back(half)], now_s);
    return;
  }
  const double reference =
      learnt_count_ >= p.test_pulse_learn_count ? learnt_sum_ / learnt_count_ : p.test_pulse_healthy_ratio;
  // Weak, and the recent half answered on the whole (not a dead drive's noise: that is the lost
  // rules' to name; run 280 was named a torque loss 42 ms before it was named lost).
  if (sum / n < p.test_pulse_weak_fraction * reference && recent >= p.test_pulse_answer_ratio) {
    if (!weak_suspect_) {
      weak_suspect_ = true;
      weak_onset_s_ = pulse_start_s;
    }
    a.confirm(Finding::ActuatorTorqueLoss, weak_onset_s_, now_s);
    rescale_after_torque_loss(recent / reference, p, a);
  } else {
    weak_suspect_ = false;
  }
}

void TorqueDetector::rescale_after_torque_loss(double remaining, const MonitorParams& p, const DiagnosisArbiter& a) {
  const Diagnosis& d = a.diagnosis(Part::Actuator);
  if (!p.torque_loss_rescales_drive || motor_scale_ != 1.0 || !d.active || d.finding != Finding::ActuatorTorqueLoss) return;
  motor_scale_ = std::clamp(remaining, p.torque_lost_threshold, 1.0);
}

}  // namespace bbw::faults
