#include "bbw/plant/delay_line.hpp"

#include <stdexcept>

namespace bbw::plant {

DelayLine::DelayLine(std::size_t capacity) : t_(capacity, 0.0), v_(capacity, 0.0) {
  if (capacity < 2) throw std::invalid_argument("DelayLine capacity must be >= 2");
}

void DelayLine::clear() {
  head_ = 0;
  size_ = 0;
}

void DelayLine::push(double time_s, double value) {
  t_[head_] = time_s;
  v_[head_] = value;
  head_ = (head_ + 1) % t_.size();
  if (size_ < t_.size()) ++size_;
}

double DelayLine::read(double time_s) const {
  if (size_ == 0) return 0.0;
  const std::size_t n = t_.size();
  // Walk from the newest sample back to the first one at or before time_s.
  std::size_t newer = (head_ + n - 1) % n;
  if (time_s >= t_[newer]) return v_[newer];
  for (std::size_t k = 1; k < size_; ++k) {
    const std::size_t older = (head_ + n - 1 - k) % n;
    if (t_[older] <= time_s) {
      const double span = t_[newer] - t_[older];
      const double w = span > 0.0 ? (time_s - t_[older]) / span : 1.0;
      return v_[older] + w * (v_[newer] - v_[older]);
    }
    newer = older;
  }
  return v_[newer];  // older than everything stored
}

}  // namespace bbw::plant
