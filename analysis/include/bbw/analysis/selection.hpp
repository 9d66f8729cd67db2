// Choosing effects: the candidates a model can still take, each scored by held-out error with
// its hyper-parameter searched on the fit part, the consistency test and the physical bounds.
// Internal to bbw_analysis.
#pragma once

#include <string>
#include <vector>

#include "bbw/analysis/design.hpp"

namespace bbw::analysis::detail {

struct Candidate {
  EffectKind kind;
  std::string name;
  int channel = -1;
};

struct Scored {
  CandidateScore score;
  Spec spec;
};

// Consistency of the held-out improvement: the held-out samples are cut into `blocks` contiguous
// chunks; t is the one-sample t statistic of log(MSE_old / MSE_new) over the chunks. The log ratio
// is scale-free, so chunks with large and small errors weigh alike, and a candidate that only fits
// noise improves some chunks and worsens others (mean near or below zero).
double paired_t(const Eigen::VectorXd& r_old, const Eigen::VectorXd& r_new, const std::vector<Index>& rows, int blocks);
// The candidates not yet in the model `s`.
std::vector<Candidate> candidates_for(const Context& c, const Spec& s);
// `s` with the candidate added at hyper-parameter `hyper`.
Spec with(const Spec& s, const Candidate& cand, double hyper);
// Searches the hyper-parameter, fits on the fit part and scores on the held-out samples.
Scored score_candidate(const Context& c, const Spec& s, const Candidate& cand, const Eigen::VectorXd& current_residual,
                       double current_holdout_rms);
// "" when the candidate's own fitted parameters are physical, else which one is not.
std::string physical_bounds_violation(const Context& c, const Spec& s, const Design& d, const Eigen::VectorXd& b,
                                      const std::string& name);
// Offset-versus-shift split of a temperature_drift step: the correlation of the two fitted
// coefficients and the offset's standard error, from sigma^2 (X'X)^-1 over the fit rows.
void split_uncertainty(const Context& c, const Spec& s, const Evaluated& ev, Step& st);

}  // namespace bbw::analysis::detail
