// The calibration state worth keeping across a fault (docs/faults.md, "Rejoin"): snapshots of
// the calibrator's curve and friction stiffnesses taken when a fit was accepted while the
// corner's sensors were trusted. A sensor fault may have been fed to the calibrator between
// its onset and its detection, so the reaction goes back to the newest snapshot taken before
// the onset. Fixed capacity; push() and before() do not allocate after construction.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/faults/bridged_curve.hpp"
#include "bbw/model/curve.hpp"

namespace bbw::faults {

struct CalibrationSnapshot {
  double time_s = 0.0;
  calibration::Curve curve;
  std::vector<double> stiffness_kN_per_rev;  // K_i, size M (sized at construction)
  bool from_fit = false;                     // false: the configured initial curve and K_i not measured
  DataSpan data;                             // where the fits up to it had data (empty: none)
};

class LastGoodCalibration {
 public:
  static constexpr std::size_t kCapacity = 4;

  // Starts with the calibrator's initial state (its initial curve and K_i: zero, or the start it was
  // given, CornerSupervisor with calibrator_friction_from_eol) as the fallback.
  explicit LastGoodCalibration(const calibration::Calibrator& initial);

  // Stores the calibrator's current curve and K_i as of time_s, its fits' data over `data`.
  void push(double time_s, const calibration::Calibrator& c, const DataSpan& data);
  // The newest snapshot taken strictly before time_s (the initial state if none).
  const CalibrationSnapshot& before(double time_s) const;
  const CalibrationSnapshot& newest() const;
  std::size_t size() const { return count_; }

 private:
  CalibrationSnapshot initial_;
  std::array<CalibrationSnapshot, kCapacity> ring_;
  std::size_t head_ = 0;   // next write
  std::size_t count_ = 0;
};

}  // namespace bbw::faults
