// Settings of the residual analysis. Plain struct; validate() names the field, value and rule.
#pragma once

#include <limits>
#include <string>
#include <vector>

namespace bbw::analysis {

// The candidate effects (issue 6). Channel candidates are generated per recorded channel.
enum class EffectKind {
  ViscousFriction,        // column: velocity
  LoadDependentFriction,  // column: fitted friction x fitted curve / max|curve|
  SensorDelay,            // position delayed by tau before every position regressor; tau searched
  TemperatureDrift,       // columns: (T - T_ref), (T - T_ref) x curve level, (T - T_ref) x curve slope
  Backlash,               // position through a play operator of width w before the model; w searched
  Creep,                  // column: curve - lag_tau(curve); tau searched
  Inertia,                // column: acceleration
  Channel,                // column: a recorded channel
  ChannelTimesVelocity,   // column: a recorded channel x velocity
};

const char* to_string(EffectKind k);
// The effect names used in config files and reports ("viscous_friction", ...); channels excluded.
const std::vector<std::string>& named_effects();

enum class HoldoutSplit {
  Interleaved,  // the recording is cut into `split_blocks` equal blocks; a spread-out 30 % is held out
  Tail,         // the last `holdout_fraction` of the recording is held out
};

struct AnalysisOptions {
  // Eq. 5 baseline. The curve is a cubic (eq. 5) when it has no knots; with knots it is a C2
  // cubic spline (the global counterpart of the calibrator's per-cycle local cubics). The
  // number of interior knots (placed at position quantiles) is chosen from curve_knots_grid:
  // the fewest knots whose held-out RMS is within curve_knots_tolerance of the best.
  std::vector<int> curve_knots_grid = {0, 1, 2, 3, 4, 6, 8};
  double curve_knots_tolerance = 0.02;
  // The friction's element thresholds (position units, smallest first). Non-empty: the model's
  // friction is exactly this element set, the online calibrator's
  // (calibration::friction_thresholds_rev of its config; bbw_analyze fills it for a recording
  // whose position is in rev), and no Delta_max is searched. Empty (a recording in another
  // unit, where the product's element set means nothing): elements_M geometric elements with
  // Delta_max chosen on delta_max_fractions of the position range by fit-part RMS.
  std::vector<double> friction_thresholds;
  int elements_M = 8;
  double geometric_ratio = 0.6;  // Delta_{i-1} = ratio * Delta_i, Delta_M = Delta_max
  // Delta_max grid, as fractions of the position range; chosen by fit-part RMS.
  std::vector<double> delta_max_fractions = {0.002, 0.005, 0.01, 0.02, 0.035, 0.05, 0.075, 0.1, 0.15, 0.2, 0.3};

  // Held-out data.
  // Held-out samples whose position lies outside the fit part's position range are not scored
  // (a candidate must not be credited or blamed for extrapolating the curve).
  HoldoutSplit split = HoldoutSplit::Interleaved;
  double holdout_fraction = 0.3;
  int split_blocks = 20;

  // Differentiators (Savitzky-Golay quadratic, centred), full window length in seconds.
  double velocity_window_s = 0.01;
  double acceleration_window_s = 0.01;

  // Acceptance rule: held-out RMS must drop by at least min_relative_drop AND the paired
  // held-out improvement (squared errors, block means) must have t >= min_t_statistic.
  double min_relative_drop = 0.05;
  double min_t_statistic = 3.0;
  int significance_blocks = 30;
  int max_steps = 6;

  // Hyper-parameter grids.
  std::vector<double> delay_grid_s = {-0.05, -0.03, -0.02, -0.015, -0.01, -0.007, -0.005, -0.003, -0.002, -0.001,
                                      0.001, 0.002, 0.003, 0.005, 0.007, 0.01, 0.015, 0.02, 0.03, 0.05};
  std::vector<double> backlash_width_fractions = {0.001, 0.002, 0.004, 0.007, 0.01, 0.015, 0.02, 0.03, 0.05};
  std::vector<double> creep_tau_s = {0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0};
  // Hyper-parameter and Delta_max searches fit on at most this many (evenly decimated) fit rows.
  int search_max_rows = 20000;

  // Which named effects are tried (channels are always tried when recorded).
  std::vector<std::string> candidates = named_effects();
  // Which added terms are attributed to the force sensor (subtracted from the reading to form the
  // clamp-force estimate) rather than to the true force. Maxwell-slip friction always is.
  // temperature_drift: only its load-cell offset column; its curve gain/shift columns are true force.
  std::vector<std::string> sensor_effects = {"viscous_friction", "load_dependent_friction", "sensor_delay",
                                             "temperature_drift"};
  // Temperature at which the load cell reads no offset; NaN: the start of the recording (median
  // of the first 100 samples), i.e. the load cell is taken as tared when the recording starts.
  double temperature_reference_C = std::numeric_limits<double>::quiet_NaN();

  // Residual structure tests.
  int ljung_box_lags = 20;
  int structure_bins = 20;
  double structure_min_eta2 = 0.05;          // share of residual variance explained by a binned variable
  double structure_min_signal_to_noise = 1.0;  // predictable residual RMS over white-noise RMS

  // Throws std::invalid_argument naming the field, its value and the rule.
  void validate() const;
  bool is_candidate(const std::string& name) const;
  bool is_sensor_effect(const std::string& name) const;
};

}  // namespace bbw::analysis
