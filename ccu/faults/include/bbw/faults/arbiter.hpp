// The arbiter: one Diagnosis per part. Detectors propose findings (confirm); the arbiter latches
// the first finding of a part, upgrades it where a later finding is worse (an actuator that
// cannot track or is lost is worse than a torque loss; one that does not release is worse than
// any other actuator finding), and names a lost process instead of a lost link.
#pragma once

#include <array>
#include <cstddef>

#include "bbw/faults/finding.hpp"

namespace bbw::faults {

class DiagnosisArbiter {
 public:
  void confirm(Finding f, double onset_s, double now_s);
  void clear(Part p) { diag_[slot(p)].active = false; }
  const Diagnosis& diagnosis(Part p) const { return diag_[slot(p)]; }
  bool ok(Part p) const { return !diag_[slot(p)].active; }

 private:
  static std::size_t slot(Part p) { return static_cast<std::size_t>(p); }
  std::array<Diagnosis, 5> diag_{};
};

}  // namespace bbw::faults
