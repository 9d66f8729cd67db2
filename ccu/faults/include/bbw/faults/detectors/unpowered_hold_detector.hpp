// A load cell on a corner whose resolver is named stuck (issue 14): the corner's controller drives
// no current then (corner_unit::ControllerParams::frozen_resolver_samples), so the drive either
// holds the load it had (the spindle's friction) or the load drives it back; the clamp force can
// only stay or fall. Once the load cell has settled at a load the pads surely carry (above the key
// friction's half-width + the end-of-line band + unpowered_min_load_margin_kN) with the motor's
// current at most unpowered_max_current_A, a held drive keeps that level: a load cell that leaves
// it by more than unpowered_kN for residual_persist_s names a load-cell offset. No position is
// needed (the residual rules need one, so they are off on such a corner): a drift or a bias that
// comes after, or goes on after, the resolver's finding (tuning seed 1401 run 394: a +1.89 kN/s
// drift on a corner whose resolver stuck 45 ms before, never named).
#pragma once

#include <array>
#include <limits>

#include "bbw/faults/detectors/detector.hpp"

namespace bbw::faults {

class UnpoweredHoldDetector {
 public:
  static constexpr int kMaxWindow = 64;
  void update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a);
  void on_rejoin() { reset(); }
  // The level the held load cell settled at (NaN while none), and the last sample's change from it.
  double reference_kN() const { return have_ref_ ? ref_kN_ : kNaN; }
  double change_kN() const { return have_ref_ ? change_kN_ : kNaN; }

 private:
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  void reset() {
    count_ = head_ = 0;
    have_ref_ = false;
    over_ = false;
    change_kN_ = 0.0;
  }
  std::array<double, kMaxWindow> lc_{};
  int count_ = 0, head_ = 0;
  bool have_ref_ = false;
  double ref_kN_ = 0.0;
  double change_kN_ = 0.0;
  bool over_ = false;
  double over_since_s_ = 0.0;
};

}  // namespace bbw::faults
