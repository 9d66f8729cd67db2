// Fixed-capacity delay line for a sampled signal with (possibly uneven) time stamps. Memory is
// sized at construction; push() and read() never allocate. Header-only (target bbw_delay_line),
// shared by the plant's sensor delay and the calibrator's load-cell delay term.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <vector>

namespace bbw::model {

class DelayLine {
 public:
  // Holds `capacity` samples (>= 2).
  explicit DelayLine(std::size_t capacity) : t_(capacity, 0.0), v_(capacity, 0.0) {
    if (capacity < 2) throw std::invalid_argument("DelayLine capacity must be >= 2");
  }

  void clear() {
    head_ = 0;
    size_ = 0;
  }

  void push(double time_s, double value) {
    t_[head_] = time_s;
    v_[head_] = value;
    head_ = head_ + 1 == t_.size() ? 0 : head_ + 1;
    if (size_ < t_.size()) ++size_;
  }

  // The value at time t (linear interpolation between stored samples). Older than the oldest
  // stored sample: the oldest value; newer than the newest: the newest value; empty: 0.
  double read(double time_s) const {
    if (size_ == 0) return 0.0;
    const std::size_t n = t_.size();
    auto before = [n](std::size_t i) { return i == 0 ? n - 1 : i - 1; };  // no division per step
    // Walk from the newest sample back to the first one at or before time_s.
    std::size_t newer = before(head_);
    if (time_s >= t_[newer]) return v_[newer];
    for (std::size_t k = 1; k < size_; ++k) {
      const std::size_t older = before(newer);
      if (t_[older] <= time_s) {
        const double span = t_[newer] - t_[older];
        const double w = span > 0.0 ? (time_s - t_[older]) / span : 1.0;
        return v_[older] + w * (v_[newer] - v_[older]);
      }
      newer = older;
    }
    return v_[newer];  // older than everything stored
  }

  // The newest stored value strictly older than time_s, no interpolation (the last sample before
  // an event); the oldest stored if none is older; empty: 0.
  double newest_before(double time_s) const {
    if (size_ == 0) return 0.0;
    const std::size_t n = t_.size();
    std::size_t i = head_;
    for (std::size_t k = 0; k < size_; ++k) {
      i = i == 0 ? n - 1 : i - 1;
      if (t_[i] < time_s) return v_[i];
    }
    return v_[i];
  }

  std::size_t size() const { return size_; }
  std::size_t capacity() const { return t_.size(); }

 private:
  std::vector<double> t_;
  std::vector<double> v_;
  std::size_t head_ = 0;  // next slot to write
  std::size_t size_ = 0;
};

}  // namespace bbw::model

// The names where they lived before model/ existed (bbw::common), so code written against them
// keeps compiling; new code says bbw::model.
namespace bbw::common {
using model::DelayLine;
}  // namespace bbw::common
