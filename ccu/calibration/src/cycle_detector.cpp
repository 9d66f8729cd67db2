#include "bbw/calibration/cycle_detector.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace bbw::calibration {

CycleDetector::CycleDetector(int n0, double margin_rev) : n0_(n0), margin_rev_(margin_rev) {
  if (n0 < 1) throw std::invalid_argument("start_lag_n0 must be >= 1, got " + std::to_string(n0));
  if (!(margin_rev >= 0.0)) throw std::invalid_argument("start_margin_rev must be >= 0");
  ring_.assign(static_cast<std::size_t>(2 * n0 + 1), 0.0);
}

void CycleDetector::reset() {
  count_ = 0;
  head_ = 0;
  was_true_ = false;
  falling_ = true;
}

bool CycleDetector::update(double x_rev) {
  const std::size_t size = ring_.size();
  head_ = (head_ + 1) % size;
  ring_[head_] = x_rev;
  ++count_;
  if (margin_rev_ > 0.0) {
    if (count_ == 1) {
      extreme_rev_ = x_rev;
      falling_ = true;
      return false;
    }
    if (falling_) {
      if (x_rev < extreme_rev_) extreme_rev_ = x_rev;
      if (x_rev > extreme_rev_ + margin_rev_) {
        falling_ = false;
        extreme_rev_ = x_rev;
        return true;
      }
    } else {
      if (x_rev > extreme_rev_) extreme_rev_ = x_rev;
      if (x_rev < extreme_rev_ - margin_rev_) {
        falling_ = true;
        extreme_rev_ = x_rev;
      }
    }
    return false;
  }
  if (count_ < size) return false;
  const std::size_t n0 = static_cast<std::size_t>(n0_);
  const double x_lag1 = ring_[(head_ + size - n0) % size];
  const double x_lag2 = ring_[(head_ + size - 2 * n0) % size];
  const bool now = x_rev > x_lag1 + margin_rev_ && x_lag1 < x_lag2 - margin_rev_;
  const bool fired = now && !was_true_;
  was_true_ = now;
  return fired;
}

double CycleDetector::recent_min_rev() const {
  const std::size_t n = std::min<std::size_t>(ring_.size(), count_);
  double m = ring_[head_];
  for (std::size_t k = 0; k < n; ++k) m = std::min(m, ring_[(head_ + ring_.size() - k) % ring_.size()]);
  return m;
}

}  // namespace bbw::calibration
