// Fixed-capacity delay line for a sampled signal with (possibly uneven) time stamps. Memory is
// sized at construction; push() and read() never allocate.
#pragma once

#include <cstddef>
#include <vector>

namespace bbw::plant {

class DelayLine {
 public:
  // Holds `capacity` samples (>= 2).
  explicit DelayLine(std::size_t capacity);

  void clear();
  void push(double time_s, double value);
  // The value at time t (linear interpolation between stored samples). Older than the oldest
  // stored sample: the oldest value; newer than the newest: the newest value.
  double read(double time_s) const;
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return t_.size(); }

 private:
  std::vector<double> t_;
  std::vector<double> v_;
  std::size_t head_ = 0;  // next slot to write
  std::size_t size_ = 0;
};

}  // namespace bbw::plant
