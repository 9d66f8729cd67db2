#include "bbw/faults/detectors/jump_detector.hpp"

#include <cmath>

#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

void JumpDetector::update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a) {
  // Across a gap (samples the guard refused, a lost link) the speed no longer predicts the step.
  if (!c.have_prev || c.dt_s > p.jump_max_gap_s) return;
  const double t = c.r.time_s;
  const double predicted = 0.5 * (c.prev.speed_rev_per_s + c.r.speed_rev_per_s) * c.dt_s;
  const double step = c.r.position_rev - c.prev.position_rev;
  const double unexplained = step - predicted;
  if (std::abs(unexplained) > p.jump_threshold_rev) {
    if (jump_pending_ && unexplained * pending_jump_rev_ < 0.0) {
      jump_pending_ = false;  // undone: a glitch, not an offset
    } else {
      jump_pending_ = true;
      pending_jump_rev_ = unexplained;
      pending_jump_s_ = t;
    }
    last_jump_s_ = t;
  }
  if (jump_pending_ && t - pending_jump_s_ >= p.jump_confirm_s) {
    jump_pending_ = false;
    a.confirm(Finding::ResolverOffset, pending_jump_s_, t);
  }
}

}  // namespace bbw::faults
