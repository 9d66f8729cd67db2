// Residual analysis (issue 6): fit the calibrator's eq. 5 model to a whole recording, then find,
// by held-out error, which candidate effect the model lacks; add it, refit, repeat; finally test
// the residual for structure that no candidate explains. Pure: no files, no clock.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "bbw/analysis/options.hpp"

namespace bbw::analysis {

struct Channel {
  std::string name;
  std::vector<double> values;
};

// A uniformly sampled recording. Optional vectors are empty when absent.
struct Recording {
  std::vector<double> time_s;
  std::vector<double> position;
  std::vector<double> force;
  std::vector<double> truth;         // true force (same unit as force), optional
  std::vector<double> temperature;   // optional
  std::vector<double> velocity;      // optional; derived from position when empty
  std::vector<double> acceleration;  // optional; derived from position when empty
  std::vector<Channel> channels;     // other recorded channels, tried as candidates
};

struct ErrorFigures {
  double rms_residual = 0.0;
  double max_residual = 0.0;
  double holdout_rms_residual = 0.0;
  bool has_truth = false;
  double rms_truth_error = 0.0;  // clamp-force estimate minus truth
  double max_truth_error = 0.0;
  // The recording may start with the friction deflected; the model's elements start relaxed.
  // Samples before the position has travelled 2 Delta_max from its running extreme
  // (calibration::StatesKnown, the online calibrator's rule) are not scored: the truth figures
  // and max_residual leave them out, and this counts them.
  std::size_t unscored_initial_samples = 0;
};

struct Parameter {
  std::string name;
  double value = 0.0;
  std::string unit;  // in terms of the recording's units: "force", "force/position", "s", ...
};

// One scored candidate in one round.
struct CandidateScore {
  std::string name;             // effect name; channels as "channel:NAME" / "channel:NAME*velocity"
  std::string hyper_name;       // "tau_s", "width", "delay_s" or empty
  double hyper_value = 0.0;
  double holdout_rms = 0.0;
  double relative_drop = 0.0;   // 1 - holdout_rms / current holdout rms
  double t_statistic = 0.0;     // paired held-out improvement, block means
  bool significant = false;
  // Why the candidate cannot be accepted whatever its scores: a fitted parameter outside its
  // physical bounds (masses, viscous coefficients, delays >= 0; creep's unrelaxed fraction in
  // [0, 1)). Empty when within bounds.
  std::string rejected_reason;
};

struct Step {
  CandidateScore evidence;
  std::string runner_up;        // the second-best candidate of that round
  double runner_up_relative_drop = 0.0;
  std::vector<Parameter> parameters;  // the effect's own fitted parameters
  double delta_max = 0.0;             // re-chosen after the step
  int curve_knots = 0;                // re-chosen after the step
  ErrorFigures errors;
  // temperature_drift: whether the load-cell offset can be told apart from the curve's own
  // shift with temperature on this recording. With the pads never open the two columns are
  // nearly collinear: |offset_shift_correlation| (of the two fitted coefficients, from the
  // fit's inverse normal matrix) >= AnalysisResult::kAmbiguousCorrelation makes the split
  // ambiguous; offset_standard_error is the offset's standard error (white-noise assumption,
  // so a lower bound). An ambiguous split calls for no online term.
  bool ambiguous = false;
  double offset_shift_correlation = 0.0;
  double offset_standard_error = 0.0;
};

struct StructureFinding {
  std::string test;       // "whiteness", "position", "time", "velocity", "channel:NAME", ...
  double statistic = 0.0; // Ljung-Box Q or F
  double critical = 0.0;
  double effect = 0.0;    // structured RMS / noise RMS (whiteness) or eta^2 (dependence)
  double effect_threshold = 0.0;
  bool significant = false;
  bool flagged = false;   // significant and effect above threshold
};

struct AnalysisResult {
  static constexpr double kAmbiguousCorrelation = 0.95;
  std::size_t samples = 0;
  double dt_s = 0.0;
  std::size_t holdout_samples = 0;
  // Gross outliers (a reading far outside its channel's bulk, e.g. one position of 1e10):
  // replaced by the channel's previous good value before anything is fitted, and counted.
  // A value counts as gross when it lies more than 10 times the 0.5-99.5 % percentile span
  // outside that span. Names: "position@1234".
  std::size_t gross_outliers = 0;
  std::vector<std::string> gross_outlier_samples;  // the first 10
  std::string differentiator;  // how velocity and acceleration were obtained

  int curve_knots = 0;  // 0: the eq. 5 cubic; else interior knots of the cubic spline
  double baseline_delta_max = 0.0;
  std::vector<Parameter> baseline_parameters;  // A..D (position units), K_i, Delta_i
  ErrorFigures baseline;
  std::vector<Step> steps;
  std::vector<Parameter> final_parameters;  // every term of the final model
  ErrorFigures final_errors;
  std::vector<std::vector<CandidateScore>> rounds;  // every round's scores, best first
  // The last round (none was accepted), then every candidate of earlier rounds refused for a
  // parameter outside its physical bounds (rejected_reason says which).
  std::vector<CandidateScore> rejected;

  std::vector<StructureFinding> structure;
  bool unexplained_structure = false;
  std::vector<std::string> structure_notes;

  // Signals for plots (full length).
  std::vector<double> residual_before, residual_after;
  std::vector<double> truth_error_before, truth_error_after;  // empty without truth
  std::string display_regressor_name;  // the first step's regressor (or position)
  std::vector<double> display_regressor;
  std::vector<double> velocity;
};

// Replaces gross outliers in position, force, truth, temperature, velocity, acceleration and the
// channels (rule above) by the previous good value of the same channel; returns how many, with
// the first 10 named in `where` when given.
std::size_t reject_gross_outliers(Recording& rec, std::vector<std::string>* where = nullptr);

// Runs the whole analysis. Throws std::invalid_argument for an unusable recording (too short,
// mismatched lengths, non-uniform or non-increasing time, constant position).
AnalysisResult analyze(const Recording& rec, const AnalysisOptions& options);

// The online calibrator's optional effect terms (its config's `effects:` keys,
// docs/calibrator.md) that the accepted steps call for: viscous_friction -> viscous_friction = 1
// (on; the calibrator fits c_v itself), sensor_delay -> force_delay_s = the measured delay,
// backlash -> backlash_width_rev = the measured width, load_dependent_friction ->
// load_friction_gain (clamped to the calibrator's [0, 10]) and load_friction_reference_kN (the
// force that gain applies at), temperature_drift -> load_cell_offset_kN_per_C (its sensor
// offset per degC; the curve's own temperature shift is tracked online by the refits) and
// load_cell_offset_reference_C. Effects without an online term (creep, inertia, recorded
// channels) give none.
struct CalibratorTerm {
  std::string key;
  double value = 0.0;
};
std::vector<CalibratorTerm> calibrator_terms(const AnalysisResult& r);

}  // namespace bbw::analysis
