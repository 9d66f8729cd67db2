// The model's structure and what is left of it: the friction's Delta_max and the curve's knots
// chosen for a model, and the tests of the final residual for structure no candidate explains.
// Internal to bbw_analysis.
#pragma once

#include "bbw/analysis/design.hpp"

namespace bbw::analysis::detail {

// Delta_max: the largest of options.friction_thresholds (the online calibrator's element set)
// when given, else chosen on the grid of fractions of the position range by the fit-part RMS.
double choose_delta_max(const Context& c, Spec s);
// Chooses the curve's knots (fewest within tolerance of the best held-out RMS) and Delta_max
// (fit-part RMS) for the model `s` otherwise as it is.
void choose_curve(const Context& c, Spec& spec);
// Whiteness and dependence tests of res.residual_after over the scored samples (from
// res.final_errors.unscored_initial_samples on): fills res.structure,
// res.unexplained_structure and res.structure_notes.
void test_structure(const Context& c, AnalysisResult& res);

}  // namespace bbw::analysis::detail
