#include "bbw/faults/last_good.hpp"

#include <algorithm>

namespace bbw::faults {

LastGoodCalibration::LastGoodCalibration(const calibration::Calibrator& initial) {
  const std::size_t m = initial.friction().stiffness_kN_per_rev.size();
  initial_.curve = initial.config().initial_curve;
  initial_.stiffness_kN_per_rev = initial.friction().stiffness_kN_per_rev;  // (zero unless it was given a start)
  initial_.from_fit = initial.prior_friction_fitted();
  for (auto& s : ring_) s.stiffness_kN_per_rev.assign(m, 0.0);
}

void LastGoodCalibration::push(double time_s, const calibration::Calibrator& c, const DataSpan& data) {
  CalibrationSnapshot& s = ring_[head_];
  s.time_s = time_s;
  s.curve = c.curve();
  const auto& k = c.friction().stiffness_kN_per_rev;
  std::copy(k.begin(), k.begin() + static_cast<std::ptrdiff_t>(std::min(k.size(), s.stiffness_kN_per_rev.size())),
            s.stiffness_kN_per_rev.begin());
  s.from_fit = true;
  s.data = data;
  head_ = (head_ + 1) % kCapacity;
  count_ = std::min(count_ + 1, kCapacity);
}

const CalibrationSnapshot& LastGoodCalibration::before(double time_s) const {
  for (std::size_t i = 0; i < count_; ++i) {
    const CalibrationSnapshot& s = ring_[(head_ + kCapacity - 1 - i) % kCapacity];
    if (s.time_s < time_s) return s;
  }
  return initial_;
}

const CalibrationSnapshot& LastGoodCalibration::newest() const {
  return count_ == 0 ? initial_ : ring_[(head_ + kCapacity - 1) % kCapacity];
}

}  // namespace bbw::faults
