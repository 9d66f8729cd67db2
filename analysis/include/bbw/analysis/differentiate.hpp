// Noise-aware differentiation of a uniformly sampled signal: centred Savitzky-Golay filters
// (least-squares quadratic over 2h+1 samples). Near the ends the window shrinks symmetrically;
// the first and last sample copy their neighbour.
#pragma once

#include <cstddef>
#include <vector>

namespace bbw::analysis {

// First derivative (slope of the local quadratic; equal to the local straight line's slope).
std::vector<double> sg_first_derivative(const std::vector<double>& x, double dt_s, std::size_t half_width);

// Second derivative (twice the curvature of the local quadratic).
std::vector<double> sg_second_derivative(const std::vector<double>& x, double dt_s, std::size_t half_width);

// Half-width in samples for a window of window_s seconds (at least 1).
std::size_t half_width_for(double window_s, double dt_s);

}  // namespace bbw::analysis
