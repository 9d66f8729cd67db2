#include "bbw/faults/arbiter.hpp"

#include <algorithm>

namespace bbw::faults {

void DiagnosisArbiter::confirm(Finding f, double onset_s, double now_s) {
  Diagnosis& d = diag_[slot(part_of(f))];
  if (d.active) {
    // An actuator that cannot track is worse than a torque loss, and one that does not release
    // is worse than any other actuator finding (its force must be counted, not just replaced):
    // the finding is upgraded (the part was isolated at the first detection). Otherwise the
    // first finding stays.
    const bool upgrade =
        ((f == Finding::ActuatorTracking || f == Finding::ActuatorLost) && d.finding == Finding::ActuatorTorqueLoss) ||
        (f == Finding::ActuatorNotReleasing && d.finding != f);
    if (upgrade) {
      d.finding = f;
      d.finding_s = now_s;
    }
    return;
  }
  if (f == Finding::ProcessLost) {
    // A lost link that turns out to be a dead process: the process is named.
    Diagnosis& link = diag_[slot(Part::Network)];
    if (link.active && link.finding == Finding::LinkLost) {
      onset_s = std::min(onset_s, link.onset_s);
      link.active = false;  // the process, not the link, is named
    }
  }
  d.present = true;
  d.active = true;
  d.finding = f;
  d.onset_s = onset_s;
  d.detected_s = now_s;
  d.finding_s = now_s;
}

}  // namespace bbw::faults
