// Tests of a residual for structure left in it: whiteness and dependence on other signals.
#pragma once

#include <string>
#include <vector>

namespace bbw::analysis {

// White-noise level from second differences (robust: MAD), valid when the structure in the
// residual is smooth over three samples: var(r[k+1] - 2 r[k] + r[k-1]) = 6 sigma^2 for white r.
double white_noise_sigma(const std::vector<double>& r);

// Upper quantile of chi-square with k degrees of freedom (Wilson-Hilferty), p = 0.01 upper tail.
double chi2_upper_1pct(double k);

struct WhitenessTest {
  double ljung_box_q = 0.0;
  double critical_q = 0.0;  // chi-square(lags) 1 % upper quantile
  int lags = 0;
  double lag1_autocorrelation = 0.0;
  double noise_rms = 0.0;       // white part (second-difference estimate)
  double structured_rms = 0.0;  // sqrt(max(0, var - noise^2))
  bool significant = false;     // Q > critical
};
WhitenessTest whiteness(const std::vector<double>& r, int lags);

// Correlation ratio eta^2 of r over equal-count bins of `by`: share of r's variance explained by
// the bin means, with the F statistic of a one-way analysis of variance.
struct DependenceTest {
  std::string against;
  double eta2 = 0.0;
  double f_statistic = 0.0;
  double f_critical = 0.0;  // chi-square(bins-1) 1 % / (bins-1): large-sample F critical value
  bool significant = false;
};
DependenceTest dependence(const std::vector<double>& r, const std::vector<double>& by, int bins,
                          const std::string& name);

}  // namespace bbw::analysis
