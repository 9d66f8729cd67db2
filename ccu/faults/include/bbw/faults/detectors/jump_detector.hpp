// Resolver offset: a position step the measured speed does not explain, not undone within
// jump_confirm_s (ResolverOffset). Its last jump also helps the residual detector name the
// resolver as the cause of a disagreement.
#pragma once

#include "bbw/faults/detectors/detector.hpp"

namespace bbw::faults {

class JumpDetector {
 public:
  void update(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a);
  double last_jump_s() const { return last_jump_s_; }
  // The sum of the confirmed jumps (rev): what the resolver's offset is, if it is one; and how
  // many were confirmed (each changes it).
  double offset_rev() const { return offset_rev_; }
  int confirmed() const { return confirmed_; }
  // Whether every step since the first sample was seen: a gap (a lost link, refused samples) may
  // hide a jump, and then the sum of the confirmed ones is not the offset.
  bool offset_tracked() const { return tracked_; }
  // A jump began at the last sample (pending its confirmation).
  bool began() const { return began_; }

 private:
  double offset_rev_ = 0.0;
  int confirmed_ = 0;
  bool began_ = false;
  bool started_ = false;
  bool tracked_ = true;
  double last_jump_s_ = -1e300;
  double pending_jump_rev_ = 0.0;
  double pending_jump_s_ = 0.0;
  bool jump_pending_ = false;
};

}  // namespace bbw::faults
