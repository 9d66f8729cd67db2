#include "bbw/faults/detectors/moving_step_detector.hpp"

#include <algorithm>
#include <cmath>

#include "bbw/faults/fault_monitor.hpp"
#include "bbw/plant/key_friction.hpp"

namespace bbw::faults {

MovingStepDetector::MovingStepDetector(const MonitorParams& p) {
  if (!p.eol_curve || !p.eol_key_friction) return;
  eol_.emplace(*p.eol_curve);
  const plant::KeyFriction keys(*p.eol_key_friction);
  std::vector<std::pair<double, double>> e;  // (swing, stiffness)
  for (std::size_t i = 0; i < keys.elements(); ++i) e.emplace_back(2.0 * keys.thresholds_rev()[i], keys.stiffness_kN_per_rev()[i]);
  std::sort(e.begin(), e.end());
  swing_rev_.resize(e.size());
  stiffness_from_kN_per_rev_.resize(e.size() + 1, 0.0);
  for (std::size_t i = e.size(); i-- > 0;) {
    swing_rev_[i] = e[i].first;
    stiffness_from_kN_per_rev_[i] = stiffness_from_kN_per_rev_[i + 1] + e[i].second;
  }
  backlash_rev_ = p.eol_backlash_rev;
  all_sticking_kN_per_rev_ = stiffness_from_kN_per_rev_.front();
}

double MovingStepDetector::friction_stiffness_kN_per_rev(double travel_rev) const {
  // The keys (the spindle) lag the motor by up to the play after a reversal.
  const double keys_travel_rev = std::max(0.0, travel_rev - backlash_rev_);
  const auto first = std::upper_bound(swing_rev_.begin(), swing_rev_.end(), keys_travel_rev) - swing_rev_.begin();
  return stiffness_from_kN_per_rev_[static_cast<std::size_t>(first)];
}

void MovingStepDetector::update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a) {
  if (!eol_ || !p.step_moving) return;
  const CornerReading& r = c.r;
  if (!c.check.load_cell_present || !c.have_prev || !c.prev_load_cell_present || c.dt_s > p.jump_max_gap_s ||
      !std::isfinite(r.force_kN) || !std::isfinite(c.prev.force_kN)) {
    reset();  // a gap: the window restarts
    return;
  }
  // A resolver named stuck reads a frozen position, and the drive moves unseen (no commutation: the
  // clamp back-drives it at 0 A). With the load cell below 0 the pads are off and it reads only
  // the spindle's friction, which vanishes when that motion stops (tuning seed 1403 run 420:
  // released from 37 kN onto the retracted stop, -3.5 -> -1.0 kN, named an offset). Such a rise
  // toward 0, not past it by more than step_kN, is not judged then; any other step is (seed 1403
  // runs 548 and 624: a drift that ended, a bias, while the resolver was stuck).
  const bool frozen = !p.step_moving_resolver_stuck_pads_off && !a.ok(Part::Resolver) &&
                      a.diagnosis(Part::Resolver).finding == Finding::ResolverStuck;
  const double temperature_C =
      std::isfinite(r.temperature_C) ? r.temperature_C : eol_->params().reference_temperature_C;
  const double eol_kN = eol_->force_kN(r.position_rev, temperature_C, 0.0);
  const double q = r.force_kN - eol_kN;
  const double dx = r.position_rev - c.prev.position_rev;
  // The travel since the last reversal (none known at the start or after a rejoin).
  const double x = r.position_rev;
  if (direction_ == 0) {
    direction_ = 1;
    turn_rev_ = extreme_rev_ = x;
  } else if ((x - extreme_rev_) * direction_ < -kReversalRev) {
    turn_rev_ = extreme_rev_;
    direction_ = -direction_;
    extreme_rev_ = x;
  } else if ((x - extreme_rev_) * direction_ > 0.0) {
    extreme_rev_ = x;
  }
  const double travel_rev = std::abs(x - turn_rev_);
  // A position step the measured speed does not explain: the resolver's, not the load cell's.
  const bool explained = std::abs(dx - r.speed_rev_per_s * c.dt_s) <= p.step_moving_unexplained_rev;
  // Where the end-of-line curve has the pads on the disc (its contact point at this temperature).
  const double contact_rev = eol_->contact_rev(temperature_C, 0.0);
  const bool trusted = r.position_rev >= contact_rev && c.prev.position_rev >= contact_rev;
  if (!explained || !trusted) {
    reset();
    return;
  }
  const auto newest = static_cast<std::size_t>((head_ - 1 + kMaxWindow) % kMaxWindow);
  // The curve's change over this sample (from the window's newest sample).
  const double deol = count_ > 0 ? eol_kN - w_[newest].eol_kN : 0.0;
  if (pending_) {
    ++kept_;
    const double dev = q - (level_kN_ + trend_kN_ * kept_);
    if (dev * step_kN_ > 0.0 && std::abs(dev) >= p.step_keep_fraction * std::abs(step_kN_)) {
      if (kept_ >= p.step_confirm_samples) {
        a.confirm(Finding::LoadCellOffset, onset_s_, r.time_s);
        reset();
      }
      return;
    }
    reset();  // returned: noise, not a bias
    return;
  }
  const int n = p.step_moving_window_samples;
  if (count_ >= n) {
    // A straight line through the window's q (least squares over u = -1 .. -n samples from now,
    // whose mean is -(n + 1) / 2 and sum of squared deviations n (n^2 - 1) / 12): the level it
    // predicts now, its slope per sample, and the spread about it.
    // The window's sums are kept as samples come and go (sum_q_: of q; sum_kq_: of k q, k the
    // samples back), so the line costs nothing per sample.
    const double u_mean = -(n + 1) / 2.0, suu = n * (static_cast<double>(n) * n - 1.0) / 12.0;
    const double trend = (-sum_kq_ - u_mean * sum_q_) / suu;
    const double level = sum_q_ / n - trend * u_mean;
    const double e = q - level;
    // The friction's largest change over this sample: from the travel before it.
    const double k_now = friction_stiffness_kN_per_rev(std::max(0.0, travel_rev - std::abs(dx)));
    const double friction_kN = k_now * std::abs(dx) + all_sticking_kN_per_rev_ * kReversalRev;
    // The rest of the allowance is never negative: only a candidate needs it (per sample, most do not).
    double spread = 0.0, max_deol = std::abs(deol), dv = std::abs(r.speed_rev_per_s - w_[newest].v_rev_per_s);
    const bool friction_vanished = frozen && level + eol_kN < 0.0 && e > 0.0 && r.force_kN <= p.step_kN;
    const bool candidate = std::abs(e) >= p.step_kN + friction_kN && !friction_vanished;
    if (candidate) {
      double sse = 0.0;
      for (int k = 1; k <= n; ++k) {
        const auto& s = w_[static_cast<std::size_t>((head_ - k + kMaxWindow) % kMaxWindow)];
        const double d = s.q_kN - (level - trend * k);
        sse += d * d;
        max_deol = std::max(max_deol, std::abs(s.deol_kN));
        if (k < n) {
          const auto& older = w_[static_cast<std::size_t>((head_ - k - 1 + kMaxWindow) % kMaxWindow)];
          dv = std::max(dv, std::abs(s.v_rev_per_s - older.v_rev_per_s));
        }
      }
      spread = std::sqrt(sse / (n - 2));
    }
    const double allowance = p.step_kN + kSpreads * spread + friction_kN + max_deol +
                             p.step_moving_speed_kN_per_rev_per_s * dv;
    if (candidate && spread <= p.step_moving_quiet_fraction * p.step_kN && std::abs(e) >= allowance) {
      pending_ = true;
      level_kN_ = level;
      trend_kN_ = trend;
      step_kN_ = e;
      onset_s_ = r.time_s;
      kept_ = 0;
      restart_window();
      return;
    }
  }
  // Every sample in the window moves one further back; the one n back leaves it.
  const double leaving = count_ >= n ? w_[static_cast<std::size_t>((head_ - n + kMaxWindow) % kMaxWindow)].q_kN : 0.0;
  sum_kq_ += sum_q_ + q - (count_ >= n ? (n + 1) * leaving : 0.0);
  sum_q_ += q - leaving;
  w_[static_cast<std::size_t>(head_)] = Sample{q, eol_kN, r.speed_rev_per_s, deol};
  head_ = (head_ + 1) % kMaxWindow;
  count_ = std::min(count_ + 1, kMaxWindow);
}

}  // namespace bbw::faults
