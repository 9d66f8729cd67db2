// Actuator tracking backstop: the force estimate against a first-order model of the commanded
// response. A shortfall below both the command and the model beyond the limit that persists:
// ActuatorTracking; an excess above both while the brake does not move back: ActuatorNotReleasing.
#pragma once

#include "bbw/faults/detectors/detector.hpp"

namespace bbw::faults {

class TrackingDetector {
 public:
  void update(const SampleContext& c, double force_estimate_kN, const MonitorParams& p, DiagnosisArbiter& a);
  void on_rejoin() {
    model_init_ = false;
    tracking_suspect_ = excess_suspect_ = false;
  }

 private:
  bool tracking_suspect_ = false;
  double tracking_onset_s_ = 0.0;
  bool excess_suspect_ = false;
  double excess_onset_s_ = 0.0;
  bool model_init_ = false;
  double model_kN_ = 0.0;
};

}  // namespace bbw::faults
