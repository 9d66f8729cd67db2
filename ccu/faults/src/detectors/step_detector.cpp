#include "bbw/faults/detectors/step_detector.hpp"

#include <algorithm>
#include <cmath>

#include "bbw/faults/fault_monitor.hpp"
#include "bbw/plant/key_friction.hpp"

namespace bbw::faults {

StepDetector::StepDetector(const MonitorParams& p) {
  if (!p.eol_key_friction) return;
  const plant::KeyFriction keys(*p.eol_key_friction);
  for (const double k : keys.stiffness_kN_per_rev()) all_sticking_kN_per_rev_ += k;
}

void StepDetector::update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a) {
  const CornerReading& r = c.r;
  if (!c.check.load_cell_present || !c.have_prev || c.dt_s > p.jump_max_gap_s) {
    reset();  // a gap: the window restarts
    if (!c.check.load_cell_present) return;
  }
  if (pending_) {
    const double dev = r.force_kN - level_kN_;
    if (dev * step_kN_ > 0.0 && std::abs(dev) >= p.step_keep_fraction * std::abs(step_kN_)) {
      if (++kept_ >= p.step_confirm_samples) {
        a.confirm(Finding::LoadCellOffset, onset_s_, r.time_s);
        reset();
      }
      return;
    }
    reset();  // returned: noise, not a bias
  }
  double level = 0.0, step_kN = 0.0;
  if (!fast(p, r.speed_rev_per_s) && still_level(p, r.position_rev, 0, kAcrossPulseSpans, level, step_kN)) {
    const double d = r.force_kN - level;
    if (std::abs(d) >= step_kN) {
      begin_step(level, d, r.time_s);
      return;
    }
  }
  x_[static_cast<std::size_t>(head_)] = r.position_rev;
  lc_[static_cast<std::size_t>(head_)] = r.force_kN;
  fast_[static_cast<std::size_t>(head_)] = fast(p, r.speed_rev_per_s);
  pulse_[static_cast<std::size_t>(head_)] = false;
  head_ = (head_ + 1) % kMaxWindow;
  count_ = std::min(count_ + 1, kMaxWindow);
}

// The still window: the last step_still_samples samples that were not a test pulse's (the newest
// `skip` left out: the sample judged, when it is already held), with the position `x_now` of the
// sample judged. A pulse splits it into segments, each of which must be still; across a pulse the
// rotor may stand `across_pulse` still spans off (the pulse's own travel, 0.1-1 mrev; the clamp
// force that moves is tens of N).
bool StepDetector::still_level(const MonitorParams& p, double x_now, int skip, double across_pulse, double& level,
                               double& step_kN) const {
  const int n = p.step_still_samples;
  if (count_ - skip < n) return false;
  double xmin = x_now, xmax = x_now, seg_min = x_now, seg_max = x_now, after = x_now, sum = 0.0;
  int changes = 0;  // a live resolver's noise moves its reading; a frozen one repeats it exactly
  int used = 0;
  bool crossed = false, split = false, still = true;
  for (int k = 1 + skip; k <= count_ && used < n; ++k) {
    const auto i = static_cast<std::size_t>((head_ - k + kMaxWindow) % kMaxWindow);
    if (pulse_[i]) {
      split = true;
      continue;
    }
    if (fast_[i]) return false;  // not still, whatever the position says
    const double x = x_[i];
    if (split) {  // the first still sample before a pulse: a new segment
      still = still && seg_max - seg_min <= p.step_still_span_rev;
      seg_min = seg_max = after = x;
      split = false;
      crossed = true;
    }
    seg_min = std::min(seg_min, x);
    seg_max = std::max(seg_max, x);
    xmin = std::min(xmin, x);
    xmax = std::max(xmax, x);
    if (x != after) ++changes;
    after = x;
    sum += lc_[i];
    ++used;
  }
  if (used < n) return false;
  still = still && seg_max - seg_min <= p.step_still_span_rev &&
          xmax - xmin <= (crossed ? across_pulse : 1.0) * p.step_still_span_rev;
  if (!still || changes < p.step_min_position_changes) return false;
  level = sum / used;
  step_kN = p.step_kN + (p.step_friction_allowance ? all_sticking_kN_per_rev_ * (xmax - xmin) : 0.0);
  return true;
}

bool StepDetector::fast(const MonitorParams& p, double speed_rev_per_s) {
  return p.step_still_max_speed_rev_per_s > 0.0 && std::abs(speed_rev_per_s) > p.step_still_max_speed_rev_per_s;
}

void StepDetector::begin_step(double level_kN, double step_kN, double time_s) {
  pending_ = true;
  level_kN_ = level_kN;
  step_kN_ = step_kN;
  onset_s_ = time_s;
  kept_ = 0;
  count_ = 0;  // the window restarts after the step, whatever it turns out to be
}

void StepDetector::on_test_pulse(int samples, double time_s, const MonitorParams& p) {
  // The pulse ended with the sample before this one (the torque rule sees its square then).
  if (pending_ || count_ < 2) return;
  const int n = std::min(samples, count_ - 1);
  for (int k = 2; k <= n + 1; ++k) pulse_[static_cast<std::size_t>((head_ - k + kMaxWindow) % kMaxWindow)] = true;
  // This sample, the first after the pulse, against the still samples before the pulse: a step
  // that came during the pulse, which its samples hid while it ran.
  const auto now = static_cast<std::size_t>((head_ - 1 + kMaxWindow) % kMaxWindow);
  double level = 0.0, step_kN = 0.0;
  if (fast_[now] || !still_level(p, x_[now], 1, kDuringPulseSpans, level, step_kN)) return;
  const double d = lc_[now] - level;
  if (std::abs(d) < step_kN) return;
  // ... and a step, not a slide: at least half of it between two samples (a bias comes at once; a
  // creeping rotor's force and a load cell's own creep move a little each sample).
  double jump = 0.0;
  for (int k = 1; k <= n + 1; ++k) {
    const auto i = static_cast<std::size_t>((head_ - k + kMaxWindow) % kMaxWindow);
    const auto before = static_cast<std::size_t>((head_ - k - 1 + kMaxWindow) % kMaxWindow);
    jump = std::max(jump, std::abs(lc_[i] - lc_[before]));
  }
  if (jump >= kStepJumpShare * std::abs(d)) begin_step(level, d, time_s);
}

}  // namespace bbw::faults
