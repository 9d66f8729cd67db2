// The bounded L-sample store of one hysteresis cycle with the normalised-distance rule (eq. 7).
//
// The first L samples after a start fill the store. Each further sample goes to slot L+1; of
// the L distances between consecutive slots, the smallest (index j) decides: j = L drops the
// new sample, otherwise one sample of the closest pair is dropped (the paper's sample j, or
// j+1 under the other reading) and the later samples shift left, so the new one ends in slot L.
// Each slot also keeps M regressor values (the element states n_i at that sample), stored as
// float: they lie in [-1, 1] (the effect regressors are scaled to order 1), float keeps them
// to 1e-7, and it halves the store (issue 13's wider element set within 24 KiB).
//
// Memory is sized at construction; add() does not allocate. Slots are addressed through an
// order array, so a shift moves small indices, not rows.
#pragma once

#include <cstdint>
#include <vector>

#include "bbw/calibration/config.hpp"

namespace bbw::calibration {

class SampleStore {
 public:
  SampleStore(int capacity_L, int row_width_M, double x_range_rev, double f_range_kN, DropRule rule);

  void clear();
  void add(double x_rev, double f_kN, const double* n_row);

  std::size_t size() const { return count_; }
  std::size_t capacity() const { return capacity_; }
  // k-th kept sample in time order, 0-based.
  double x_rev(std::size_t k) const { return x_[order_[k]]; }
  double f_kN(std::size_t k) const { return f_[order_[k]]; }
  const float* n_row(std::size_t k) const { return &n_[order_[k] * width_]; }
  double min_x_rev() const;
  double max_x_rev() const;
  std::uint64_t dropped() const { return dropped_; }

  std::size_t bytes() const;

 private:
  double dist2(std::size_t a, std::size_t b) const;  // logical indices
  void write(std::size_t phys, double x, double f, const double* n_row);

  std::size_t capacity_;
  std::size_t width_;
  double inv_x2_;
  double inv_f2_;
  DropRule rule_;
  std::vector<double> x_, f_;         // capacity + 1 physical slots
  std::vector<float> n_;
  std::vector<std::uint32_t> order_;  // logical slot -> physical slot
  std::vector<double> d2_;            // d2_[k]: squared distance between logical k and k + 1
  std::size_t count_ = 0;
  std::uint64_t dropped_ = 0;
  // Index of the smallest of d2_[0 .. L-2] (the pairs that stay when a new sample is dropped),
  // kept up to date so that the common case, a new sample closest to its predecessor, costs
  // O(1); a drop of an older sample rescans (the paper notes the minimum can be kept
  // incrementally).
  std::size_t settled_min_ = 0;
  void rescan_settled_min();
};

}  // namespace bbw::calibration
