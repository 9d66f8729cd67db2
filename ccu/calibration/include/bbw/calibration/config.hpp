// Calibrator settings. Plain struct; validate() names the field, value and rule it breaks.
#pragma once

#include <cmath>
#include <cstddef>

#include <string>
#include <vector>

#include "bbw/model/curve.hpp"
#include "bbw/model/effect_terms.hpp"

namespace bbw::calibration {

enum class Mode { Paper, Robust };
enum class ThresholdSpacing { Even, Geometric };
// Which sample of the closest pair the distance rule drops (the paper's text is ambiguous).
enum class DropRule { DropJ, DropJPlus1 };

struct CalibratorConfig {
  Mode mode = Mode::Robust;

  int elements_M = 8;        // Maxwell-slip elements
  int samples_L = 64;        // samples kept per cycle
  int pf_points_N = 20;      // N + 1 principal fitting points
  int start_lag_n0 = 10;     // cycle-start detector lag, samples
  double delta_max_rev = 0.3;  // largest element threshold

  double x_min_rev = 0.0;    // displacement range of the PF points and distance rule
  double x_max_rev = 7.0;
  double f_min_kN = 0.0;     // force range of the distance rule
  double f_max_kN = 50.0;
  double full_scale_kN = 40.0;  // for error in % of full scale

  Curve initial_curve{};     // starting A, B, C, D

  // Samples outside these are rejected and counted (corrupt, not physical).
  double accept_position_min_rev = -2.0;
  double accept_position_max_rev = 12.0;
  double accept_force_min_kN = -10.0;
  double accept_force_max_kN = 100.0;

  DropRule drop_rule = DropRule::DropJ;

  // Robust-mode choices (ignored in paper mode, which uses the paper's plain method).
  bool scale_x = true;               // fit in x scaled to [-1, 1]
  bool nonnegative_k = true;         // K_i >= 0 by non-negative least squares
  double min_cycle_span_rev = 0.3;   // no update from a cycle narrower than this
  ThresholdSpacing spacing = ThresholdSpacing::Geometric;
  double geometric_ratio = 0.6;      // Delta_{i} = Delta_{i+1} * ratio (smallest first)
  bool streaming_states = true;      // element states updated every sample, rows stored
  double ridge = 1e-6;               // Tikhonov weight per stored row on the scaled problem
  double max_fit_rms_kN = 1.0;       // reject a cycle fit whose residual RMS exceeds this
  double start_margin_rev = 0.02;    // robust start detector hysteresis (0 = the paper's eq. 6)
  double k_smoothing = 1.0;          // weight of a new fit's friction stiffness (1 = replace)
  bool identify_per_element = true;  // update K_i only when the cycle span >= 2 Delta_i
  // Friction memory: each cycle's information on the friction amplitudes (its normal
  // equations with the cycle's curve deviation eliminated) is added to the past information
  // times friction_memory, and the amplitudes are solved from the sum. A cycle then moves an
  // element only as far as it informs it. 0 = off (each cycle fitted alone and the amplitudes
  // averaged with k_smoothing); in (0, 1].
  double friction_memory = 0.0;
  // Load-cell noise passes straight into f_hat = f_c - friction. The estimate is the curve at
  // the present position plus the mean of the last residual_window residuals
  // r = f_c - friction - C(x) (the curve error and friction misfit vary slowly; the noise is
  // white), so the noise falls by sqrt(window). 1 = off; at most kMaxResidualWindow samples.
  int residual_window = 1;
  static constexpr int kMaxResidualWindow = 64;

  // Optional model terms for effects found offline (./bbw analyze), per caliper: the objects of
  // bbw/model/effect_terms.hpp (EffectTerms) hold their bounds, columns and arithmetic.
  // viscous_friction: a load-cell term c_v * v (v = resolver speed, or the slope of the last
  // velocity_window positions when the sample carries no speed), fitted with K_i, c_v >= 0.
  bool viscous_friction = false;
  double viscous_speed_scale_rev_per_s = 10.0;  // regressor scaling inside the fit
  int velocity_window = 9;                      // samples, for the position-slope fallback
  // force_delay_s: the load cell lags the resolver by this much (a sensor or filter delay
  // ./bbw analyze measures; 0 = off, at most 0.05). The model pairs each load-cell reading with
  // the position force_delay_s earlier (a delay line sized for up to 2.5 kHz, force_delay_slots), and
  // the estimate is carried to the present along the curve:
  //   f_hat(t) = f_c(t) - friction(x(t - d)) + C(x(t)) - C(x(t - d)).
  double force_delay_s = 0.0;
  static constexpr std::size_t kForceDelayCapacity = 128;
  // Delay-line slots for a delay d: enough at up to 2.5 kHz (ceil(d * 2500) + 3), at most
  // kForceDelayCapacity; 2 when off (issue 13: 16 slots for 5 ms keep the state within 24 KiB).
  static std::size_t force_delay_slots(double force_delay_s) {
    if (!(force_delay_s > 0.0)) return 2;
    const double slots = std::ceil(force_delay_s * 2500.0) + 3.0;
    return slots >= static_cast<double>(kForceDelayCapacity) ? kForceDelayCapacity : static_cast<std::size_t>(slots);
  }
  // load_friction_gain: the key friction grows with the clamp force (./bbw analyze's
  // load_dependent_friction: friction_gain_at_full_curve at its reference_force):
  //   friction = sum_i K_i Delta_i n_i * (1 + g max(C(x), 0) / F_ref),
  // with C the current curve. The element regressors are scaled by that factor and K_i fitted
  // as before. 0 = off; at most 10.
  double load_friction_gain = 0.0;
  double load_friction_reference_kN = 40.0;
  // backlash_width_rev: play between the resolver (motor side) and the spindle that loads the
  // pads (./bbw analyze's backlash.width). The model runs on the spindle position, the play
  // operator of the resolver position: inside the gap the spindle stays where it was. 0 = off;
  // at most 0.5.
  double backlash_width_rev = 0.0;
  // load_cell_offset_kN_per_C: the load cell's zero drifts with temperature (./bbw analyze's
  // temperature_drift: sensor_offset_per_degC about reference_temperature_C). The calibrator
  // removes k (T - T_ref) from every reading before the model sees it, T = the sample's
  // temperature (the last finite one when a sample has none; T_ref before the first).
  // 0 = off; |k| at most 1.
  double load_cell_offset_kN_per_C = 0.0;
  double load_cell_offset_reference_C = 40.0;

  // Friction measured before any fit (a caliper's end-of-line keys, faults::calibrator_start):
  // the elements' K_i (empty: none; else elements_M of them, each >= 0), the viscous coefficient
  // (used with viscous_friction) and the weight the friction memory holds them with as its prior
  // (Calibrator::set_friction_prior). The calibrator starts from them, its friction counting as
  // fitted once the element states are known.
  std::vector<double> initial_stiffness_kN_per_rev;
  double initial_viscous_kN_per_rev_per_s = 0.0;
  double initial_friction_weight = 0.0;

  // The effect terms' values (EffectTerms), as the calibrator is configured.
  EffectTermValues effect_values() const;
  // Regressor columns the effect terms add (effect_columns).
  int effect_columns() const { return calibration::effect_columns(effect_values()); }

  // Throws std::invalid_argument naming the field, its value and the rule.
  void validate() const;
};

const char* to_string(Mode m);

// The friction's element thresholds Delta_i (rev, smallest first) of a calibrator with this
// config: geometric from delta_max_rev down (robust mode, geometric spacing) or even. The one
// place the friction's structure is computed: the online calibrator runs it and ./bbw analyze
// fits it (issue 13: the same method in one place).
std::vector<double> friction_thresholds_rev(const CalibratorConfig& config);

}  // namespace bbw::calibration
