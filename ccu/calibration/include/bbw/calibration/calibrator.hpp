// The real-time caliper calibrator (docs/calibrator.md, ../shared/docs/calibration-algorithm.md).
//
// Pure: no DDS, no clock, no file, no thread. Memory is sized at construction; update() does
// not allocate. The same object runs per sample in the CCU, offline over a CSV and in tests.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "bbw/calibration/bounded_lsq.hpp"
#include "bbw/calibration/config.hpp"
#include "bbw/calibration/cycle_detector.hpp"
#include "bbw/calibration/sample_store.hpp"
#include "bbw/model/curve.hpp"
#include "bbw/model/delay_line.hpp"
#include "bbw/model/maxwell_slip.hpp"
#include "bbw/model/states_known.hpp"

namespace bbw::calibration {

struct Sample {
  double time_s = 0.0;
  double position_rev = 0.0;  // resolver position, actuator revolutions
  double force_kN = 0.0;      // internal load-cell reading (true force + key friction)
  double speed_rev_per_s = std::numeric_limits<double>::quiet_NaN();  // resolver speed; NaN = not given
  double temperature_C = std::numeric_limits<double>::quiet_NaN();  // caliper temperature; NaN = not given
};

struct Estimate {
  double force_kN = 0.0;        // f_hat = load cell minus estimated friction
  double friction_kN = 0.0;     // estimated key/keyway friction sum K_i Delta_i n_i (+ c_v v when enabled)
  double viscous_kN = 0.0;      // the c_v v part of friction_kN (0 without the viscous term)
  double curve_force_kN = 0.0;  // A x^3 + B x^2 + C x + D at the sample's position
  bool valid = false;           // false when the sample was rejected (NaN, out of range, time backwards)
  bool calibrated = false;      // true once at least one cycle fit was accepted
  // The friction term is a fitted one where the keys are: its K_i come from accepted fits (this
  // calibrator's, those of the snapshot a restarted one was given, or a caliper's measured ones:
  // set_friction_stiffness(k, true)) and every element's state is known (the position has swept 2 Delta_max since the
  // start). A restarted calibrator has it before its first fit of its own (calibrated).
  bool friction_fitted = false;
  bool cycle_start = false;     // a new hysteresis cycle started at this sample
  bool fit_accepted = false;    // a cycle-end fit was accepted at this sample
};

struct Stats {
  std::uint64_t samples_seen = 0;
  std::uint64_t samples_rejected = 0;  // non-finite, out of the configured range, time backwards
  std::uint64_t cycles_detected = 0;
  std::uint64_t fits_accepted = 0;
  std::uint64_t fits_rejected = 0;
  std::uint64_t fits_held = 0;         // cycles ended while fits were held (hold_fits): not fitted
  double first_fit_time_s = -1.0;      // time of the first accepted fit; -1 before it
  double last_fit_rms_kN = 0.0;        // residual RMS of the last cycle fit
  double last_fit_span_rev = 0.0;      // displacement span of the last cycle fitted
  // The positions the curve's accepted fits had samples over (their union; lo > hi before any):
  // elsewhere its PF points keep the initial curve's values.
  double curve_data_min_rev = 1.0;
  double curve_data_max_rev = 0.0;
};

// Friction part of the model: thresholds Delta_i (rev) and stiffnesses K_i (kN/rev).
struct FrictionParams {
  std::vector<double> delta_rev;
  std::vector<double> stiffness_kN_per_rev;
  double viscous_kN_per_rev_per_s = 0.0;  // c_v, when the viscous term is enabled
};

class Calibrator {
 public:
  explicit Calibrator(const CalibratorConfig& config);  // throws std::invalid_argument

  // One sample in, one estimate out. Never allocates.
  Estimate update(const Sample& sample);

  const Curve& curve() const { return curve_; }
  const FrictionParams& friction() const { return friction_; }
  const Stats& stats() const { return stats_; }
  const CalibratorConfig& config() const { return config_; }
  // PF points: X_k = Xmin + k (Xmax - Xmin) / N and their force coordinates.
  const std::vector<double>& pf_positions_rev() const { return pf_x_rev_; }
  const std::vector<double>& pf_forces_kN() const { return pf_f_kN_; }

  // Restart from a known curve (e.g. a restarted corner's last good curve). Keeps stats and K_i.
  void reset_curve(const Curve& curve);
  // Friction stiffnesses from elsewhere (e.g. the last good state); sizes must match M.
  // from_fits: they were fitted, or measured like a fit (a caliper's end-of-line key friction):
  // Estimate::friction_fitted once the states are known.
  void set_friction_stiffness(const std::vector<double>& k_kN_per_rev, bool from_fits = false);
  // Friction stiffnesses measured elsewhere (a caliper's end-of-line key friction), as
  // set_friction_stiffness(k, true), and with friction memory also as its prior: each element's
  // amplitude K_i Delta_i counts as `weight` of information (the sum of n_i^2 over a cycle's rows
  // it would take to carry as much), forgotten by friction_memory per accepted fit like a cycle's.
  // A cycle that cannot tell an element's friction from the curve (it never turned the element
  // round) then leaves it at the measured value rather than at the ridge's 0. With the viscous term
  // (CalibratorConfig::viscous_friction) its coefficient likewise, from viscous_kN_per_rev_per_s.
  // Sizes must match M; weight >= 0 (0: no prior).
  void set_friction_prior(const std::vector<double>& k_kN_per_rev, double weight, double viscous_kN_per_rev_per_s = 0.0);
  // Whether the K_i it was given are such (set_friction_stiffness's from_fits).
  bool prior_friction_fitted() const { return prior_friction_fitted_; }
  // Where the current curve already had data before this calibrator (a restart from a snapshot):
  // joined into Stats::curve_data_* as an accepted fit's span is. Ignored when empty (lo > hi).
  void note_prior_curve_data(double lo_rev, double hi_rev) { note_curve_data(lo_rev, hi_rev); }

  // While held, a cycle that ends is not fitted (counted in Stats::fits_held) and a new cycle
  // starts as usual: the CCU holds fits while its fault monitor suspects the load cell, so a
  // fault's first samples are never learnt as the caliper's curve (docs/faults.md).
  void hold_fits(bool held) { fits_held_ = held; }

  // Bytes owned by this object (itself plus its buffers), for the memory budget.
  std::size_t state_bytes() const;

 private:
  bool fits_held_ = false;
  void start_cycle(double x_rev);
  void note_curve_data(double x_lo_rev, double x_hi_rev);  // Stats::curve_data_*
  bool end_cycle();
  template <class F>
  void for_each_fit_row(std::size_t columns, F&& f);
  void refit_curve_from_pf();
  void regressor_row(double x_rev, const double* n, double* row) const;
  double poly_basis_x(double x_rev, int power) const;
  // The curve the residual window carries its residuals along: the curve over [x_min, x_max], its
  // value at x_min below (flat), its tangent at x_max above.
  double carrying_curve_kN(double x_rev) const;

  CalibratorConfig config_;
  bool robust_;
  bool streaming_;
  bool scaled_;
  bool nonneg_;
  int m_;      // elements
  int e_;      // regressor columns of the effect terms (CalibratorConfig::effect_columns)
  int p_;      // parameters per fit: 4 + M + E
  double xc_rev_, xh_rev_;  // scaling x_s = (x - xc) / xh

  Curve curve_;
  FrictionParams friction_;
  Stats stats_;
  std::vector<double> phi_kN_;    // K_i Delta_i, the friction amplitude of element i
  std::vector<double> pf_x_rev_;
  std::vector<double> pf_f_kN_;
  std::vector<double> pf_proj_;   // 4 x (N+1): PF forces -> scaled cubic coefficients

  CycleDetector detector_;
  SampleStore store_;
  bool in_cycle_ = false;
  std::uint64_t samples_since_start_ = 0;
  double last_time_s_ = 0.0;
  bool have_time_ = false;
  // Streaming element states are exact once x has moved 2 Delta_max from its running lowest
  // or highest position (every element has then slipped, whatever its initial deflection);
  // cycle starts before that are ignored.
  StatesKnown states_known_rule_;
  bool states_known_ = false;
  bool prior_friction_fitted_ = false;  // set_friction_stiffness(k, true)
  std::vector<char> identified_;  // per phi: identified by at least one accepted fit

  std::vector<double> element_pos_rev_;  // live element positions x_i
  std::vector<double> n_now_;            // live n_i, then the extra regressors
  std::vector<double> vel_t_s_, vel_x_rev_;  // ring of recent samples for the speed fallback
  common::DelayLine position_delay_;     // positions for the force-delay term (2 slots when off)
  std::size_t vel_head_ = 0, vel_count_ = 0;
  double speed_now(const Sample& s);
  // Load-dependent friction: the factor on the element regressors at x (1 when off).
  double load_scale(double x_rev) const;
  // Backlash: the spindle position (play operator of the resolver position; state below).
  double spindle_rev_ = 0.0;
  // Load-cell thermal offset: the last finite temperature (the reference until one arrives).
  double temperature_C_ = 0.0;
  std::vector<double> start_pos_rev_;    // x0_i at the current cycle's start (replay)
  // Residual averaging (config residual_window): ring of the last residuals f_c - friction - C(x).
  std::vector<double> residual_kN_;
  std::size_t residual_head_ = 0, residual_count_ = 0;

  // Fit workspace, sized at construction.
  BoundedLeastSquares solver_;
  std::vector<double> gram_;
  std::vector<double> rhs_;
  std::vector<double> theta_;
  std::vector<double> row_;       // regressors of the columns taking part
  std::vector<double> full_row_;  // all p_ regressors of one sample
  std::vector<double> n_replay_;
  std::vector<double> pos_replay_;
  std::vector<char> column_on_;
  std::vector<int> column_map_;
  std::vector<char> nonneg_flags_;
  bool end_cycle_with_memory();
  // Friction memory (config friction_memory): the summed information on the amplitudes
  // (packed upper triangle by rows, float) and its right-hand side; empty when off.
  std::vector<float> info_kN_;
  std::vector<double> info_rhs_kN_;
};

}  // namespace bbw::calibration
