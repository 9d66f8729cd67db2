#include "bbw/faults/detectors/jump_detector.hpp"

#include <algorithm>
#include <cmath>

#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

void JumpDetector::update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a) {
  began_ = false;
  // Across a gap (samples the guard refused, a lost link) the speed no longer predicts the step,
  // and a jump within it goes unseen.
  if (!c.have_prev || c.dt_s > p.jump_max_gap_s) {
    if (started_) tracked_ = false;
    started_ = true;
    return;
  }
  started_ = true;
  const double t = c.r.time_s;
  // The step is explained anywhere between what the two measured speeds give over the interval
  // (the speed changed monotonically within it): a drive that seizes at 20 rev/s stops within one
  // sample, and the trapezoid's prediction put half its last step, 0.01-0.02 rev, down to the
  // resolver (a seized drive named resolver_offset: stress seed 1406 run 360, tune_b run 528).
  const double lo = std::min(c.prev.speed_rev_per_s, c.r.speed_rev_per_s) * c.dt_s;
  const double hi = std::max(c.prev.speed_rev_per_s, c.r.speed_rev_per_s) * c.dt_s;
  const double step = c.r.position_rev - c.prev.position_rev;
  const double unexplained = step < lo ? step - lo : step > hi ? step - hi : 0.0;
  if (std::abs(unexplained) > p.jump_threshold_rev) {
    if (jump_pending_ && unexplained * pending_jump_rev_ < 0.0) {
      jump_pending_ = false;  // undone: a glitch, not an offset
    } else {
      jump_pending_ = true;
      began_ = true;
      pending_jump_rev_ = unexplained;
      pending_jump_s_ = t;
    }
    last_jump_s_ = t;
  }
  if (jump_pending_ && t - pending_jump_s_ >= p.jump_confirm_s) {
    jump_pending_ = false;
    offset_rev_ += pending_jump_rev_;
    ++confirmed_;
    a.confirm(Finding::ResolverOffset, pending_jump_s_, t);
  }
}

}  // namespace bbw::faults
