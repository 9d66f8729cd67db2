// A caliper population: seeded draws of e-calipers that differ in key friction (element count,
// threshold distribution and span, half-width, force shares, initial deflection), clamp curve
// (contact point, stiffness, temperature behaviour) and load-cell noise, around a base plant.
// Pure: no files; the same (ranges, seed, index) always gives the same caliper, and member i
// does not depend on how many members are drawn. docs/plant.md ("Caliper population").
#pragma once

#include <cstdint>
#include <string>

#include "bbw/plant/params.hpp"

namespace bbw::plant {

struct Interval {
  double min = 0.0;
  double max = 0.0;
};

// What varies and how much. Intervals are drawn uniformly unless the name says log.
struct PopulationRanges {
  Interval elements{10, 60};                      // integer, uniform
  Interval threshold_min_rev{0.002, 0.05};        // smallest threshold, log-uniform
  Interval threshold_span_ratio{3.0, 400.0};      // largest / smallest threshold, log-uniform
  double threshold_max_limit_rev = 0.8;           // the largest threshold is clipped to this
  double log_uniform_share = 0.5;                 // fraction of calipers with log-uniform thresholds
  Interval half_width_kN{0.5, 2.0};
  Interval force_share_exponent{-0.5, 1.0};
  Interval share_log_sigma{0.0, 1.0};             // uneven force shares
  Interval initial_deflection{-1.0, 1.0};         // friction state at the recording's start
  Interval contact_rev{0.2, 1.0};
  Interval stiffness_scale{0.7, 1.3};             // on exp_coefficient_kN and linear_kN_per_rev
  Interval contact_shift_rev_per_C{0.002, 0.006};
  Interval stiffness_change_per_C{-0.006, -0.002};
  Interval load_cell_noise_kN{0.02, 0.05};

  void validate() const;  // throws std::invalid_argument naming the field
};

// One drawn caliper: its plant parameters and a one-line description of the key friction.
struct Caliper {
  int index = 0;
  std::uint64_t seed = 0;      // the member's own seed (SplitMix64 of population seed and index)
  PlantParams params;
  double stiffness_scale = 1.0;
};

// Member `index` of the population (seed, ranges) around `base`. Throws std::invalid_argument.
Caliper draw_caliper(const PlantParams& base, const PopulationRanges& ranges, std::uint64_t seed, int index);

// "40 el, log-uniform 0.004-0.22 rev, 1.10 kN" (thresholds as drawn, not the ranges).
std::string describe_key_friction(const KeyFrictionParams& k);

}  // namespace bbw::plant
