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

 private:
  double last_jump_s_ = -1e300;
  double pending_jump_rev_ = 0.0;
  double pending_jump_s_ = 0.0;
  bool jump_pending_ = false;
};

}  // namespace bbw::faults
