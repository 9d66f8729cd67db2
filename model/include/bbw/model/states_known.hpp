// The StatesKnown rule: from which sample on the Maxwell-slip element states no longer depend on
// the friction's unknown initial deflection. Pure arithmetic, no allocation.
#pragma once

#include <cstddef>

namespace bbw::model {

// When the element states are known whatever the friction's initial deflection: once x has
// moved 2 Delta_max from its running lowest or highest position, every element (the real
// one and a model started relaxed alike) has been dragged to x -/+ Delta_i. Shared by the
// online calibrator (cycle starts before it are ignored) and ./bbw analyze (samples before it
// are not scored).
class StatesKnown {
 public:
  explicit StatesKnown(double delta_max) : two_delta_(2.0 * delta_max) {}
  // Feeds one position; true from the sample at which the states are known on.
  bool update(double x) {
    if (known_) return true;
    if (!started_) {
      low_ = high_ = x;
      started_ = true;
    }
    low_ = x < low_ ? x : low_;
    high_ = x > high_ ? x : high_;
    known_ = x - low_ >= two_delta_ || high_ - x >= two_delta_;
    return known_;
  }
  bool known() const { return known_; }

 private:
  double two_delta_;
  double low_ = 0.0, high_ = 0.0;
  bool started_ = false;
  bool known_ = false;
};

// Index of the first sample at which the states are known (n when never).
inline std::size_t first_known_sample(const double* x, std::size_t n, double delta_max) {
  StatesKnown s(delta_max);
  for (std::size_t k = 0; k < n; ++k) {
    if (s.update(x[k])) return k;
  }
  return n;
}

}  // namespace bbw::model

// The names where they lived before model/ existed (bbw::calibration), so code written against them
// keeps compiling; new code says bbw::model.
namespace bbw::calibration {
using model::StatesKnown;
using model::first_known_sample;
}  // namespace bbw::calibration
