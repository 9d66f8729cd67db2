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
//
// A rotor that was accelerating when the resolver froze coasts on unseen after its current is cut
// (twenty-fourth session, tuning seed 1401 run 341: frozen at 0.39 rev/s while a 40 A loop was
// turning a 72 % torque loss's drive round at 2 kN, the current cut 25 ms later; the spindle's
// reflected 3e-3 kg m^2 against a 0.1 Nm load coasted 0.1 s and raised the clamp force 0.6 kN).
// With unpowered_coast_bound the frozen speed is not taken as the speed: from the last sample the
// resolver changed, a bound on the spindle's forward speed integrates what the measured current
// can make less what the load (the load cell less the keys' half-width) and the drive's friction
// take, (torque_per_A i - Nm_per_kN F - friction(w)) / (2 pi J), never below 0; the rule holds
// only while that bound is within unpowered_max_speed_rev_per_s.
#pragma once

#include <array>

#include "bbw/faults/detectors/detector.hpp"

namespace bbw::faults {

class UnpoweredHoldDetector {
 public:
  static constexpr int kMaxWindow = 64;
  // commutation_lost: the resolver is named stuck (FaultMonitor::commutation_lost).
  void update(const SampleContext& c, bool commutation_lost, const MonitorParams& p, DiagnosisArbiter& a);
  void on_rejoin() {
    reset();
    have_coast_ = false;
  }
  // The bound on the spindle's forward speed (rev/s) the detector holds the rule to.
  double forward_speed_bound_rev_per_s() const { return forward_bound_rev_per_s_; }

 private:
  void reset() {
    count_ = head_ = 0;
    have_ref_ = false;
    over_ = false;
  }
  void track_coast(const SampleContext& c, const MonitorParams& p);
  std::array<double, kMaxWindow> lc_{};
  bool have_coast_ = false;
  double forward_bound_rev_per_s_ = 0.0;
  int count_ = 0, head_ = 0;
  bool have_ref_ = false;
  double ref_kN_ = 0.0;
  bool over_ = false;
  double over_since_s_ = 0.0;
};

}  // namespace bbw::faults
