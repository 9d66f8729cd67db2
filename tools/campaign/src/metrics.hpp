// Campaign statistics (pure): binomial confidence intervals for coverage, a Poisson upper bound
// for the false-alarm rate, percentiles for latencies.
#pragma once

#include <vector>

namespace bbw::campaign {

struct Interval {
  double lo = 0.0;
  double hi = 1.0;
};

// Two-sided 95 % intervals of a proportion k / n (n > 0): Wilson score and Clopper-Pearson
// (exact: the beta quantiles, found by bisection on the binomial distribution).
Interval wilson95(long long k, long long n);
Interval clopper_pearson95(long long k, long long n);

// One-sided 95 % upper bound of a Poisson mean after observing k events (exact: P(X <= k) = 0.05;
// k = 0 gives 2.996).
double poisson_upper95(long long k);

// The p-quantile (0..1) of the values by linear interpolation between order statistics (NaN when
// empty). Sorts a copy.
double percentile(std::vector<double> values, double p);

}  // namespace bbw::campaign
