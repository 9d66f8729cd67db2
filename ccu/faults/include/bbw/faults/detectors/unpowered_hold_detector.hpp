// A load cell on a corner whose resolver is named stuck (issue 14, nineteenth session): the
// corner's controller drives no current then (corner_unit::ControllerParams::frozen_resolver_samples),
// so a drive that held when the resolver froze (its frozen speed within
// unpowered_max_speed_rev_per_s; one frozen at speed coasts on, the force rising) keeps its clamp
// force, or the load drives the spindle back and the force falls; nothing raises it. With the
// motor's current within unpowered_max_current_A, the mean of the last unpowered_settle_samples
// load-cell values is the reference while it is at a load the pads surely carry (the key
// friction's half-width + the end-of-line band + unpowered_min_load_margin_kN); it follows that
// mean down, never up, and a load cell above it by more than unpowered_kN for residual_persist_s
// names a load-cell offset. No position is needed (the residual and step rules need one, so they
// are off on such a corner): tuning seed 1401 run 394, a +1.89 kN/s drift 45 ms after the
// resolver stuck in a hard stop, never named before.
#pragma once

#include <array>

#include "bbw/faults/detectors/detector.hpp"

namespace bbw::faults {

class UnpoweredHoldDetector {
 public:
  static constexpr int kMaxWindow = 64;
  // commutation_lost: the resolver is named stuck (FaultMonitor::commutation_lost).
  void update(const SampleContext& c, bool commutation_lost, const MonitorParams& p, DiagnosisArbiter& a);
  void on_rejoin() { reset(); }

 private:
  void reset() {
    count_ = head_ = 0;
    have_ref_ = false;
    over_ = false;
  }
  std::array<double, kMaxWindow> lc_{};
  int count_ = 0, head_ = 0;
  bool have_ref_ = false;
  double ref_kN_ = 0.0;
  bool over_ = false;
  double over_since_s_ = 0.0;
};

}  // namespace bbw::faults
