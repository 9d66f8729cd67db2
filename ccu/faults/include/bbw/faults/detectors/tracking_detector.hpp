// Actuator tracking backstop: the force estimate against a first-order model of the commanded
// response. A shortfall below both the command and the model beyond the limit that persists:
// ActuatorTracking; an excess above both while the brake does not move back: ActuatorNotReleasing.
// `friction_kN`: the calibrated key friction (load cell minus clamp force) when the load cell is
// trusted, else 0. The corner's loop holds its load cell at the command, so a healthy clamp force
// stands off the command by that friction: the part of a shortfall or excess it explains is not
// counted (a caliper with 3 kN of key friction held its clamp force 3 kN above a falling command).
// `clamp_upper_kN`: the most clamp force the measured position allows (NaN: no bound); the excess
// counts no force above it (MonitorParams::tracking_excess_position_bound). `clamp_lower_kN`: the
// least (NaN: 0); the shortfall counts no force below it (tracking_shortfall_position_bound).
#pragma once

#include "bbw/faults/detectors/detector.hpp"

namespace bbw::faults {

class TrackingDetector {
 public:
  void update(const SampleContext& c, double force_estimate_kN, double friction_kN, double clamp_upper_kN,
              double clamp_lower_kN, const MonitorParams& p, DiagnosisArbiter& a);
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
