#include "bbw/faults/detectors/step_detector.hpp"

#include <algorithm>
#include <cmath>

#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

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
  const int n = p.step_still_samples;
  if (count_ >= n) {
    double xmin = r.position_rev, xmax = r.position_rev, sum = 0.0, after = r.position_rev;
    int changes = 0;  // a live resolver's noise moves its reading; a frozen one repeats it exactly
    for (int k = 1; k <= n; ++k) {
      const int i = (head_ - k + kMaxWindow) % kMaxWindow;
      const double x = x_[static_cast<std::size_t>(i)];
      xmin = std::min(xmin, x);
      xmax = std::max(xmax, x);
      if (x != after) ++changes;
      after = x;
      sum += lc_[static_cast<std::size_t>(i)];
    }
    const double level = sum / n;
    const double d = r.force_kN - level;
    if (xmax - xmin <= p.step_still_span_rev && changes >= p.step_min_position_changes && std::abs(d) >= p.step_kN) {
      pending_ = true;
      level_kN_ = level;
      step_kN_ = d;
      onset_s_ = r.time_s;
      kept_ = 0;
      count_ = 0;  // the window restarts after the step, whatever it turns out to be
      return;
    }
  }
  x_[static_cast<std::size_t>(head_)] = r.position_rev;
  lc_[static_cast<std::size_t>(head_)] = r.force_kN;
  head_ = (head_ + 1) % kMaxWindow;
  count_ = std::min(count_ + 1, kMaxWindow);
}

}  // namespace bbw::faults
