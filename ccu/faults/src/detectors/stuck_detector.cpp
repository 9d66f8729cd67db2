#include "bbw/faults/detectors/stuck_detector.hpp"

#include <algorithm>

#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

namespace {
// A run of exact repeats beyond what the channel's live noise ever gives, and beyond the run
// factor times the longest run it ended by itself.
bool frozen(int run, int longest_healthy_run, const MonitorParams& p) {
  return p.stuck_frozen_run_factor > 0.0 && run >= p.stuck_frozen_samples &&
         run >= p.stuck_frozen_run_factor * longest_healthy_run;
}
}  // namespace

void StuckDetector::update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a) {
  if (!c.have_prev) return;
  const CornerReading& r = c.r;
  const CornerReading& prev = c.prev;
  const double t = r.time_s;
  // Stuck load cell: the same value again while the position travels.
  if (c.check.load_cell_present && c.prev_load_cell_present && r.force_kN == prev.force_kN) {
    if (lc_repeat_ == 0) {
      lc_run_onset_s_ = prev.time_s;
      run_pos_min_ = run_pos_max_ = prev.position_rev;
    }
    ++lc_repeat_;
    run_pos_min_ = std::min(run_pos_min_, r.position_rev);
    run_pos_max_ = std::max(run_pos_max_, r.position_rev);
    if (lc_repeat_ >= p.stuck_samples && run_pos_max_ - run_pos_min_ >= p.stuck_min_travel_rev) {
      a.confirm(Finding::LoadCellStuck, lc_run_onset_s_, t);
    }
    if (frozen(lc_repeat_, longest_lc_run_, p)) a.confirm(Finding::LoadCellStuck, lc_run_onset_s_, t);
  } else {
    if (c.check.load_cell_present) longest_lc_run_ = std::max(longest_lc_run_, lc_repeat_);  // ended by itself
    lc_repeat_ = 0;
  }
  // Frozen resolver: position and speed (a separate, unquantised measurement) both repeated.
  if (r.position_rev == prev.position_rev && r.speed_rev_per_s == prev.speed_rev_per_s) {
    if (resolver_frozen_ == 0) resolver_frozen_onset_s_ = prev.time_s;
    ++resolver_frozen_;
    if (frozen(resolver_frozen_, longest_resolver_run_, p)) a.confirm(Finding::ResolverStuck, resolver_frozen_onset_s_, t);
  } else {
    longest_resolver_run_ = std::max(longest_resolver_run_, resolver_frozen_);
    resolver_frozen_ = 0;
  }
  // A resolver diagnosed stuck that lives again (its unquantised speed changes every sample).
  const Diagnosis& rd = a.diagnosis(Part::Resolver);
  if (rd.active && rd.finding == Finding::ResolverStuck) {
    resolver_live_run_ = r.speed_rev_per_s != prev.speed_rev_per_s ? resolver_live_run_ + 1 : 0;
    if (resolver_live_run_ >= p.stuck_resolver_clear_samples) {
      a.clear(Part::Resolver);
      resolver_cleared_ = true;
      resolver_live_run_ = 0;
    }
  } else {
    resolver_live_run_ = 0;
  }
  // Stuck resolver: the same position again while the load cell changes.
  if (r.position_rev == prev.position_rev && c.check.load_cell_present) {
    if (pos_repeat_ == 0) {
      pos_run_onset_s_ = prev.time_s;
      run_lc_min_ = run_lc_max_ = r.force_kN;
    }
    ++pos_repeat_;
    run_lc_min_ = std::min(run_lc_min_, r.force_kN);
    run_lc_max_ = std::max(run_lc_max_, r.force_kN);
    if (pos_repeat_ >= p.stuck_samples && run_lc_max_ - run_lc_min_ >= p.stuck_min_force_change_kN) {
      a.confirm(Finding::ResolverStuck, pos_run_onset_s_, t);
    }
  } else if (r.position_rev != prev.position_rev) {
    pos_repeat_ = 0;
  }
}

}  // namespace bbw::faults
