#include "bbw/faults/fault_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace bbw::faults {
namespace {

void require(bool ok, const char* field, double value, const char* rule) {
  if (!ok) throw std::invalid_argument(std::string("MonitorParams.") + field + " = " + std::to_string(value) + ": " + rule);
}
void positive(const char* field, double v) { require(std::isfinite(v) && v > 0.0, field, v, "must be > 0"); }

std::size_t slot(Part p) { return static_cast<std::size_t>(p); }

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
  require(std::isfinite(curve_min_rev), "curve_min_rev", curve_min_rev, "must be finite");
  require(std::isfinite(curve_max_rev) && curve_max_rev > curve_min_rev, "curve_max_rev", curve_max_rev,
          "must be finite and > curve_min_rev");
  positive("jump_threshold_rev", jump_threshold_rev);
  positive("jump_confirm_s", jump_confirm_s);
  positive("jump_window_s", jump_window_s);
  require(stuck_samples >= 2, "stuck_samples", stuck_samples, "must be >= 2");
  positive("stuck_min_travel_rev", stuck_min_travel_rev);
  positive("stuck_min_force_change_kN", stuck_min_force_change_kN);
  require(frozen_attribution_samples >= 2, "frozen_attribution_samples", frozen_attribution_samples, "must be >= 2");
  require(noise_window_samples >= 4 && noise_window_samples <= kMaxNoiseWindow, "noise_window_samples",
          noise_window_samples, "must be in [4, 256]");
  positive("noise_step_kN", noise_step_kN);
  require(noise_min_fraction > 0.0 && noise_min_fraction <= 1.0, "noise_min_fraction", noise_min_fraction,
          "must be in (0, 1]");
  require(dropout_samples >= 1, "dropout_samples", dropout_samples, "must be >= 1");
  positive("torque_per_A_Nm", torque_per_A_Nm);
  positive("Nm_per_kN", Nm_per_kN);
  require(torque_fraction_threshold > 0.0 && torque_fraction_threshold < 1.0, "torque_fraction_threshold",
          torque_fraction_threshold, "must be in (0, 1)");
  positive("inertia_kg_m2", inertia_kg_m2);
  positive("torque_filter_s", torque_filter_s);
  positive("torque_check_min_torque_Nm", torque_check_min_torque_Nm);
  require(torque_lost_threshold > 0.0 && torque_lost_threshold < torque_fraction_threshold, "torque_lost_threshold",
          torque_lost_threshold, "must be in (0, torque_fraction_threshold)");
  positive("torque_lost_persist_s", torque_lost_persist_s);
  positive("torque_check_min_load_kN", torque_check_min_load_kN);
  positive("torque_check_max_speed_rev_per_s", torque_check_max_speed_rev_per_s);
  positive("torque_persist_s", torque_persist_s);
  positive("tracking_time_constant_s", tracking_time_constant_s);
  positive("tracking_threshold_kN", tracking_threshold_kN);
  require(tracking_relative >= 0.0 && tracking_relative < 1.0, "tracking_relative", tracking_relative,
          "must be in [0, 1)");
  positive("tracking_persist_s", tracking_persist_s);
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

FaultMonitor::FaultMonitor(const MonitorParams& params, Target corner)
    : p_((params.validate(), params)),
      corner_(corner),
      curve_min_rev_(params.curve_min_rev),
      curve_max_rev_(params.curve_max_rev) {
  if (!corner_slot(corner)) throw std::invalid_argument("FaultMonitor: monitors a corner, not the CCU");
}

void FaultMonitor::confirm(Finding f, double onset_s, double now_s) {
  Diagnosis& d = diag_[slot(part_of(f))];
  if (d.active) {
    // An actuator that cannot track is worse than a torque loss, and one that does not release
    // is worse than any other actuator finding (its force must be counted, not just replaced):
    // the finding is upgraded (the part was isolated at the first detection). Otherwise the
    // first finding stays.
    const bool upgrade =
        ((f == Finding::ActuatorTracking || f == Finding::ActuatorLost) && d.finding == Finding::ActuatorTorqueLoss) ||
        (f == Finding::ActuatorNotReleasing && d.finding != f);
    if (upgrade) {
      d.finding = f;
      d.finding_s = now_s;
    }
    return;
  }
  if (f == Finding::ProcessLost) {
    // A lost link that turns out to be a dead process: the process is named.
    Diagnosis& link = diag_[slot(Part::Network)];
    if (link.active && link.finding == Finding::LinkLost) {
      onset_s = std::min(onset_s, link.onset_s);
      link.active = false;  // the process, not the link, is named
    }
  }
  d.present = true;
  d.active = true;
  d.finding = f;
  d.onset_s = onset_s;
  d.detected_s = now_s;
  d.finding_s = now_s;
}

void FaultMonitor::set_curve_range(double min_rev, double max_rev) {
  curve_min_rev_ = std::max(min_rev, p_.curve_min_rev);
  curve_max_rev_ = std::min(max_rev, p_.curve_max_rev);
}

void FaultMonitor::clear(Part p) { diag_[slot(p)].active = false; }

bool FaultMonitor::take_rejoin() {
  const bool r = rejoined_;
  rejoined_ = false;
  process_lost_since_rejoin_ = false;
  return r;
}

void FaultMonitor::on_link_event(LinkEvent e, double time_s) {
  switch (e) {
    case LinkEvent::DeadlineMissed:
      if (ok(Part::Process)) confirm(Finding::LinkLost, any_arrival_ ? last_arrival_s_ : time_s, time_s);
      break;
    case LinkEvent::LivelinessLost:
      confirm(Finding::ProcessLost, any_arrival_ ? last_arrival_s_ : time_s, time_s);
      process_lost_since_rejoin_ = true;
      break;
    case LinkEvent::LivelinessRecovered: break;  // samples arriving decide the rejoin
    case LinkEvent::Restarted:
      // Faster than the participant lease (2 s) when the launcher restarts the process within it.
      if (ok(Part::Process)) {
        confirm(Finding::ProcessLost, any_arrival_ ? last_arrival_s_ : time_s, time_s);
        process_lost_since_rejoin_ = true;
      }
      break;
  }
}

void FaultMonitor::tick(double now_s) {
  if (any_arrival_ && now_s - last_arrival_s_ > p_.deadline_s && ok(Part::Network) && ok(Part::Process)) {
    confirm(Finding::LinkLost, last_arrival_s_, now_s);
  }
}

void FaultMonitor::update(const CornerReading& r, const SampleCheck& check, const calibration::Estimate* estimate,
                          double force_estimate_kN, double arrival_s) {
  // Any arrival, even a corrupt one, shows that the corner is there.
  if (!ok(Part::Network) || !ok(Part::Process)) {
    clear(Part::Network);
    clear(Part::Process);
    rejoined_ = true;
    have_prev_ = false;           // no continuity across the gap
    have_prev_residual_ = false;
    model_init_ = false;
    residual_suspect_ = tracking_suspect_ = excess_suspect_ = torque_suspect_ = lost_suspect_ = false;
    torque_init_ = false;
    lc_repeat_ = pos_repeat_ = missing_run_ = 0;
  }
  any_arrival_ = true;
  last_arrival_s_ = arrival_s;
  if (!check.usable()) return;  // corrupt: counted by the guard, never used

  const double t = r.time_s;
  const double dt_s = have_prev_ ? t - prev_.time_s : 0.0;

  // Dropout.
  if (!check.load_cell_present) {
    if (missing_run_ == 0) missing_onset_s_ = t;
    if (++missing_run_ >= p_.dropout_samples) confirm(Finding::LoadCellMissing, missing_onset_s_, t);
  } else {
    missing_run_ = 0;
  }

  if (have_prev_) {
    // Resolver jump: a position step the measured speed does not explain.
    const double predicted = 0.5 * (prev_.speed_rev_per_s + r.speed_rev_per_s) * dt_s;
    const double step = r.position_rev - prev_.position_rev;
    const double unexplained = step - predicted;
    if (std::abs(unexplained) > p_.jump_threshold_rev) {
      if (jump_pending_ && unexplained * pending_jump_rev_ < 0.0) {
        jump_pending_ = false;  // undone: a glitch, not an offset
      } else {
        jump_pending_ = true;
        pending_jump_rev_ = unexplained;
        pending_jump_s_ = t;
      }
      last_jump_s_ = t;
    }
    if (jump_pending_ && t - pending_jump_s_ >= p_.jump_confirm_s) {
      jump_pending_ = false;
      confirm(Finding::ResolverOffset, pending_jump_s_, t);
    }

    // Stuck load cell: the same value again while the position travels.
    if (check.load_cell_present && prev_lc_present_ && r.load_cell_kN == prev_.load_cell_kN) {
      if (lc_repeat_ == 0) {
        lc_run_onset_s_ = prev_.time_s;
        run_pos_min_ = run_pos_max_ = prev_.position_rev;
      }
      ++lc_repeat_;
      run_pos_min_ = std::min(run_pos_min_, r.position_rev);
      run_pos_max_ = std::max(run_pos_max_, r.position_rev);
      if (lc_repeat_ >= p_.stuck_samples && run_pos_max_ - run_pos_min_ >= p_.stuck_min_travel_rev) {
        confirm(Finding::LoadCellStuck, lc_run_onset_s_, t);
      }
    } else {
      lc_repeat_ = 0;
    }
    // Stuck resolver: the same position again while the load cell changes.
    if (r.position_rev == prev_.position_rev && check.load_cell_present) {
      if (pos_repeat_ == 0) {
        pos_run_onset_s_ = prev_.time_s;
        run_lc_min_ = run_lc_max_ = r.load_cell_kN;
      }
      ++pos_repeat_;
      run_lc_min_ = std::min(run_lc_min_, r.load_cell_kN);
      run_lc_max_ = std::max(run_lc_max_, r.load_cell_kN);
      if (pos_repeat_ >= p_.stuck_samples && run_lc_max_ - run_lc_min_ >= p_.stuck_min_force_change_kN) {
        confirm(Finding::ResolverStuck, pos_run_onset_s_, t);
      }
    } else if (r.position_rev != prev_.position_rev) {
      pos_repeat_ = 0;
    }
  }

  if (estimate != nullptr && estimate->valid) check_residual(r, *estimate);
  check_actuator(r, check, force_estimate_kN, dt_s);

  prev_ = r;
  prev_lc_present_ = check.load_cell_present;
  have_prev_ = true;
}

void FaultMonitor::check_residual(const CornerReading& r, const calibration::Estimate& e) {
  const double t = r.time_s;
  residual_kN_ = e.force_kN - e.curve_force_kN;
  check_noise(residual_kN_, t);
  if (r.position_rev < curve_min_rev_ || r.position_rev > curve_max_rev_) {
    residual_suspect_ = false;  // no trusted curve here
    residual_kN_ = std::numeric_limits<double>::quiet_NaN();
    residual_change_kN_ = std::numeric_limits<double>::quiet_NaN();
    have_reference_ = false;  // restarts where the curve is trusted again
    return;
  }
  // The first accepted fit replaces the initial curve and adds the friction model, which moves
  // the residual by itself: the change rule restarts from the calibrated residual, unless a
  // fault is already suspected. (Later fits move it little; restarting at each of them too made
  // a slow drift 40 ms later to find.)
  if (e.calibrated != reference_calibrated_ && !residual_suspect_) have_reference_ = false;
  if (!have_reference_) {
    have_reference_ = true;
    reference_calibrated_ = e.calibrated;
    reference_kN_ = residual_kN_;
    reference_time_s_ = t;
  }
  residual_change_kN_ = residual_kN_ - reference_kN_;
  const double thr = e.calibrated ? p_.residual_threshold_kN : p_.uncalibrated_residual_threshold_kN;
  const bool over = std::abs(residual_kN_) > thr || (e.calibrated && std::abs(residual_change_kN_) > p_.residual_change_threshold_kN);
  if (!over) {
    residual_suspect_ = false;
    const double dt = std::max(0.0, t - reference_time_s_);
    reference_kN_ += (residual_kN_ - reference_kN_) * -std::expm1(-dt / p_.residual_reference_s);
    reference_time_s_ = t;
    return;
  }
  reference_time_s_ = t;  // frozen while suspected
  if (!residual_suspect_) {
    residual_suspect_ = true;
    residual_onset_s_ = t;
  }
  if (t - residual_onset_s_ < p_.residual_persist_s) return;
  // Isolation: which channel explains the disagreement?
  const bool position_frozen = pos_repeat_ >= p_.frozen_attribution_samples;
  const bool load_cell_frozen = lc_repeat_ >= p_.frozen_attribution_samples;
  Finding f = Finding::LoadCellOffset;
  if (position_frozen && !load_cell_frozen) {
    f = Finding::ResolverStuck;
  } else if (load_cell_frozen && !position_frozen) {
    f = Finding::LoadCellStuck;
  } else if (t - last_jump_s_ <= p_.jump_window_s + p_.residual_persist_s) {
    f = Finding::ResolverOffset;
  }
  confirm(f, residual_onset_s_, t);
}

void FaultMonitor::check_noise(double residual_kN, double t) {
  if (!have_prev_residual_) {
    have_prev_residual_ = true;
    prev_residual_kN_ = residual_kN;
    return;
  }
  const double d = residual_kN - prev_residual_kN_;
  prev_residual_kN_ = residual_kN;
  const int w = p_.noise_window_samples;
  const auto h = static_cast<std::size_t>(noise_head_);
  if (noise_count_ == w) noise_big_count_ -= noise_big_[h];
  noise_big_[h] = std::abs(d) > p_.noise_step_kN ? 1 : 0;
  noise_big_count_ += noise_big_[h];
  noise_head_ = (noise_head_ + 1) % w;
  if (noise_count_ < w) ++noise_count_;
  noise_kN_ = static_cast<double>(noise_big_count_) / w;
  if (noise_kN_ >= p_.noise_min_fraction) confirm(Finding::LoadCellNoisy, t, t);
}

void FaultMonitor::check_actuator(const CornerReading& r, const SampleCheck& c, double force_estimate_kN,
                                  double dt_s) {
  const double t = r.time_s;
  // Torque balance: needed (load + acceleration) against made (current), filtered.
  const double load_kN = c.load_cell_present && ok(Part::LoadCell) ? r.load_cell_kN : force_estimate_kN;
  const double accel = have_prev_ && dt_s > 0.0 ? (r.speed_rev_per_s - prev_.speed_rev_per_s) / dt_s : 0.0;
  if (!ok(Part::Resolver) || !std::isfinite(load_kN)) {
    torque_init_ = torque_suspect_ = lost_suspect_ = false;
  } else {
    constexpr double kTwoPi = 6.283185307179586;
    const double need = load_kN * p_.Nm_per_kN + p_.inertia_kg_m2 * kTwoPi * accel;
    const double make = r.motor_current_A * p_.torque_per_A_Nm;
    if (!torque_init_ || dt_s <= 0.0) {
      torque_init_ = true;
      need_Nm_ = need;
      make_Nm_ = make;
    } else {
      const double a = -std::expm1(-dt_s / p_.torque_filter_s);
      need_Nm_ += (need - need_Nm_) * a;
      make_Nm_ += (make - make_Nm_) * a;
    }
    const bool checkable = load_kN >= p_.torque_check_min_load_kN && make_Nm_ >= p_.torque_check_min_torque_Nm;
    const double fraction = checkable ? need_Nm_ / make_Nm_ : 1.0;
    if (checkable) torque_fraction_ = fraction;
    if (checkable && fraction < p_.torque_lost_threshold) {
      if (!lost_suspect_) {
        lost_suspect_ = true;
        lost_onset_s_ = t;
      }
      if (t - lost_onset_s_ >= p_.torque_lost_persist_s) confirm(Finding::ActuatorLost, lost_onset_s_, t);
    } else {
      lost_suspect_ = false;
    }
    const bool still = std::abs(r.speed_rev_per_s) <= p_.torque_check_max_speed_rev_per_s;
    if (checkable && still && fraction < p_.torque_fraction_threshold) {
      if (!torque_suspect_) {
        torque_suspect_ = true;
        torque_onset_s_ = t;
      }
      if (t - torque_onset_s_ >= p_.torque_persist_s) confirm(Finding::ActuatorTorqueLoss, torque_onset_s_, t);
    } else {
      torque_suspect_ = false;
    }
  }

  // Tracking against a first-order model of the commanded response.
  const double cmd = r.force_command_kN;
  if (!std::isfinite(cmd) || !std::isfinite(force_estimate_kN)) {
    model_init_ = false;
    tracking_suspect_ = excess_suspect_ = false;
    return;
  }
  if (!model_init_ || dt_s <= 0.0) {
    model_init_ = true;
    model_kN_ = force_estimate_kN;
  } else {
    model_kN_ += (cmd - model_kN_) * -std::expm1(-dt_s / p_.tracking_time_constant_s);
  }
  // A shortfall counts below both the command and the model, an excess above both (a release
  // faster than the model, or an apply faster than it, is not a fault).
  const double limit = std::max(p_.tracking_threshold_kN, p_.tracking_relative * std::abs(cmd));
  const bool reachable = cmd <= p_.force_limit_kN;
  if (reachable && std::min(cmd, model_kN_) - force_estimate_kN > limit) {
    if (!tracking_suspect_) {
      tracking_suspect_ = true;
      tracking_onset_s_ = t;
    }
    if (t - tracking_onset_s_ >= p_.tracking_persist_s) confirm(Finding::ActuatorTracking, tracking_onset_s_, t);
  } else {
    tracking_suspect_ = false;
  }
  // Over-application: the brake holds a force well above what it is told and was told. Any
  // command counts (a brake told to release must release, whatever the force limit).
  const bool moving_back = r.speed_rev_per_s < -p_.release_min_speed_rev_per_s;
  if (!moving_back && force_estimate_kN - std::max(cmd, model_kN_) > limit) {
    if (!excess_suspect_) {
      excess_suspect_ = true;
      excess_onset_s_ = t;
    }
    if (t - excess_onset_s_ >= p_.tracking_persist_s) confirm(Finding::ActuatorNotReleasing, excess_onset_s_, t);
  } else {
    excess_suspect_ = false;
  }
}

}  // namespace bbw::faults
