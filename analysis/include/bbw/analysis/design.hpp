// The regressor design of one model (eq. 5 baseline plus candidate effect columns) on a whole
// recording, its bounded least-squares fit and its error figures. Internal to bbw_analysis
// (analysis.cpp, selection.cpp, structure.cpp); not part of the public interface.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "bbw/analysis/analysis.hpp"
#include "bbw/analysis/options.hpp"

namespace bbw::analysis::detail {

using Index = Eigen::Index;
using Vec = std::vector<double>;

struct ColumnEffect {
  EffectKind kind;
  std::string name;   // report name
  double hyper = 0.0; // tau_s for creep
  int channel = -1;
};

// The model: eq. 5 on an effective position (delayed and/or through a play operator) plus
// extra columns.
struct Spec {
  double delta_max = 0.0;
  std::vector<double> knots;  // interior spline knots in scaled position; empty: eq. 5 cubic
  bool has_delay = false;
  double delay_s = 0.0;
  bool has_backlash = false;
  double backlash_width = 0.0;
  std::vector<ColumnEffect> columns;
};

struct Design {
  Eigen::MatrixXd x;
  std::vector<bool> nonneg;
  std::vector<int> owner;  // -2 curve, -1 friction, >= 0 index into Spec::columns
  Vec deltas;
  Vec x_eff;
  // The first sample at which the element states are known (calibration::StatesKnown on x_eff
  // with the largest threshold; n when never): rows before it are neither fitted nor scored.
  std::size_t first_known = 0;
};

struct Context {
  Context(const Recording& r, const AnalysisOptions& o) : rec(r), opt(o) {}
  const Recording& rec;
  const AnalysisOptions& opt;
  std::size_t n = 0;
  double dt = 0.0;
  double xmin = 0.0, xmax = 0.0, xrange = 0.0;
  Vec v, a;
  double temp_ref = 0.0;
  Eigen::VectorXd y;
  std::vector<Index> train, train_search, holdout;
  // From the last accepted fit: the curve and the friction, for columns built on them.
  Vec ref_curve, ref_friction, ref_slope;
  double ref_curve_scale = 1.0, ref_slope_scale = 1.0;
};

struct Evaluated {
  Design design;
  Eigen::VectorXd coef;
  Eigen::VectorXd residual;
  ErrorFigures errors;
  Vec truth_error;
};

double rms_of(const Eigen::VectorXd& r, const std::vector<Index>& rows);
// The columns an effect adds (one, or three for temperature_drift).
std::vector<Vec> column_values(const Context& c, const ColumnEffect& e);
// The position the model sees: delayed and/or through the play operator.
Vec effective_position(const Context& c, const Spec& s);
Design build(const Context& c, const Spec& s);
// The rows of `rows` (ascending) the fit uses, and the held-out rows that are scored: those
// from d.first_known on, as the online
// calibrator starts no cycle before its element states are known; all of `rows` when fewer
// than twice the model's columns would be left (a recording that never travels 2 Delta_max).
std::vector<Index> fit_rows(const Design& d, const std::vector<Index>& rows);
// The bounded least-squares fit on fit_rows(d, rows).
Eigen::VectorXd fit(const Context& c, const Design& d, const std::vector<Index>& rows);
// Residual, error figures (scored samples only) and the estimate's error against the truth.
Evaluated evaluate(const Context& c, const Spec& s, Design d, const Eigen::VectorXd& coef);
// The fit-part RMS on the decimated search rows (hyper-parameter and Delta_max searches).
double search_rms(const Context& c, const Spec& s);
// Refreshes the curve, friction and slope some columns are built on from the fit `ev`.
void update_refs(Context& c, const Evaluated& ev);
// Every term of the model, curve coefficients back in position units.
std::vector<Parameter> model_parameters(const Context& c, const Spec& s, const Evaluated& ev);
// The parameters named "NAME.*".
std::vector<Parameter> effect_parameters(const std::vector<Parameter>& all, const std::string& name);
// The signal the report plots the residual against for an effect.
Vec display_signal(const Context& c, const Spec& s, const std::string& name);

}  // namespace bbw::analysis::detail
