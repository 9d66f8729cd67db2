// Stuck channels: a load cell repeating its value exactly while the position travels
// (LoadCellStuck), a resolver repeating its position while the load cell changes
// (ResolverStuck); and at any motion, a channel frozen for longer than its live noise ever
// repeats (the load cell; the resolver's position and speed together). The run lengths also tell
// the residual detector which channel is frozen.
#pragma once

#include "bbw/faults/detectors/detector.hpp"

namespace bbw::faults {

class StuckDetector {
 public:
  void update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a);
  void on_rejoin() { lc_repeat_ = pos_repeat_ = resolver_frozen_ = 0; }
  int load_cell_repeats() const { return lc_repeat_; }
  int position_repeats() const { return pos_repeat_; }
  // A stuck-resolver finding cleared (the resolver lives again); true once per clearing.
  bool take_resolver_cleared() {
    const bool c = resolver_cleared_;
    resolver_cleared_ = false;
    return c;
  }

 private:
  int lc_repeat_ = 0;
  double lc_run_onset_s_ = 0.0;
  double run_pos_min_ = 0.0, run_pos_max_ = 0.0;
  int pos_repeat_ = 0;
  double pos_run_onset_s_ = 0.0;
  double run_lc_min_ = 0.0, run_lc_max_ = 0.0;
  // Position and speed both repeated; the longest runs each channel ended by itself.
  int resolver_frozen_ = 0;
  double resolver_frozen_onset_s_ = 0.0;
  int longest_lc_run_ = 0, longest_resolver_run_ = 0;
  int resolver_live_run_ = 0;  // consecutive samples whose speed changed, while diagnosed stuck
  bool resolver_cleared_ = false;
};

}  // namespace bbw::faults
