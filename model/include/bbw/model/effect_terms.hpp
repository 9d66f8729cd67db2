// The calibrator's optional effect terms (docs/calibrator.md, "Optional effect terms"), one object
// each, in one list. A term names its YAML key (under `effects:`) and its parameters with their
// bounds (the one copy: the YAML loader, CalibratorConfig::validate and the wire codec's from_msg
// all check through it), says how many regressor columns it adds to the calibrator's fit, and
// holds the arithmetic the calibrator applies and a corner's FrictionTracker replays.
// Stateless, header-only, no allocation: the per-sample calls inline to what they were.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <tuple>

#include "bbw/model/play.hpp"

namespace bbw::model {

// The values of the terms, as the calibrator is configured and as a corner replays them.
struct EffectTermValues {
  bool viscous = false;                    // the viscous column is fitted (calibrator side)
  double viscous_kN_per_rev_per_s = 0.0;   // c_v, the fitted coefficient (corner side; 0 = off)
  double viscous_speed_scale_rev_per_s = 10.0;
  double force_delay_s = 0.0;
  double backlash_width_rev = 0.0;
  double load_friction_gain = 0.0;
  double load_friction_reference_kN = 40.0;
  double load_cell_offset_kN_per_C = 0.0;
  double load_cell_offset_reference_C = 40.0;
};

// One bounded parameter: finite and in [min, max], or (min, max] when min_open.
struct TermBound {
  const char* key;  // the CalibratorConfig field and its YAML key under effects:
  double min;
  double max;
  bool min_open;
  bool contains(double v) const { return std::isfinite(v) && (min_open ? v > min : v >= min) && v <= max; }
};

inline constexpr double kNoUpperBound = std::numeric_limits<double>::infinity();

// A parameter that breaks its bound: which, and the value.
struct TermViolation {
  const TermBound* bound = nullptr;  // null: none
  double value = 0.0;
  explicit operator bool() const { return bound != nullptr; }
};

namespace detail {
inline TermViolation check(const TermBound& b, double v) { return b.contains(v) ? TermViolation{} : TermViolation{&b, v}; }
}  // namespace detail

// Viscous friction c_v v on the load cell, fitted with K_i (one regressor column, c_v >= 0).
struct ViscousTerm {
  static constexpr const char* key = "viscous_friction";
  static constexpr TermBound coefficient{"viscous_kN_per_rev_per_s", 0.0, kNoUpperBound, false};
  static constexpr TermBound speed_scale{"viscous_speed_scale_rev_per_s", 0.0, kNoUpperBound, true};
  static TermViolation check(const EffectTermValues& v) {
    if (auto e = detail::check(coefficient, v.viscous_kN_per_rev_per_s)) return e;
    return detail::check(speed_scale, v.viscous_speed_scale_rev_per_s);
  }
  static int columns(const EffectTermValues& v) { return v.viscous ? 1 : 0; }
  static double friction_kN(double c_v, double speed_rev_per_s) { return c_v * speed_rev_per_s; }
};

// The load cell lags the resolver by d: the model runs on the position d earlier (calibrator only;
// a corner's loop closes on its present load cell, so the tracker has nothing to replay).
struct ForceDelayTerm {
  static constexpr const char* key = "force_delay_s";
  static constexpr TermBound delay{"force_delay_s", 0.0, 0.05, false};
  static TermViolation check(const EffectTermValues& v) { return detail::check(delay, v.force_delay_s); }
  static int columns(const EffectTermValues&) { return 0; }
  static bool on(double force_delay_s) { return force_delay_s > 0.0; }
};

// Backlash: the model runs on the spindle position, the play operator of the resolver position.
struct BacklashTerm {
  static constexpr const char* key = "backlash_width_rev";
  static constexpr TermBound width{"backlash_width_rev", 0.0, 0.5, false};
  static TermViolation check(const EffectTermValues& v) { return detail::check(width, v.backlash_width_rev); }
  static int columns(const EffectTermValues&) { return 0; }
  static bool on(double width_rev) { return width_rev > 0.0; }
  static double spindle_rev(double& spindle_state_rev, double x_rev, double width_rev) {
    return play_step(spindle_state_rev, x_rev, width_rev);
  }
};

// Load-dependent key friction: the element friction times 1 + g max(F, 0) / F_ref, F the curve's
// clamp force (the element regressors scaled by it; no column of its own).
struct LoadFrictionTerm {
  static constexpr const char* key = "load_friction_gain";
  static constexpr TermBound gain{"load_friction_gain", 0.0, 10.0, false};
  static constexpr TermBound reference{"load_friction_reference_kN", 0.0, kNoUpperBound, true};
  static TermViolation check(const EffectTermValues& v) {
    if (auto e = detail::check(gain, v.load_friction_gain)) return e;
    return detail::check(reference, v.load_friction_reference_kN);
  }
  static int columns(const EffectTermValues&) { return 0; }
  static bool on(double g) { return g > 0.0; }
  static double scale(double g, double reference_kN, double force_kN) {
    return 1.0 + g * (force_kN > 0.0 ? force_kN : 0.0) / reference_kN;
  }
};

// The load cell's thermal zero offset k (T - T_ref), removed before the model sees a reading.
struct LoadCellOffsetTerm {
  static constexpr const char* key = "load_cell_offset_kN_per_C";
  static constexpr TermBound slope{"load_cell_offset_kN_per_C", -1.0, 1.0, false};
  static constexpr TermBound reference{"load_cell_offset_reference_C", -50.0, 150.0, false};
  static TermViolation check(const EffectTermValues& v) {
    if (auto e = detail::check(slope, v.load_cell_offset_kN_per_C)) return e;
    return detail::check(reference, v.load_cell_offset_reference_C);
  }
  static int columns(const EffectTermValues&) { return 0; }
  static bool on(double k) { return k != 0.0; }
  static double offset_kN(double k_kN_per_C, double reference_C, double temperature_C) {
    return k_kN_per_C * (temperature_C - reference_C);
  }
};

// The list. A new term: its object above, a place here, its replay in FrictionTracker, its
// regressor in the calibrator, its field in CalibrationState (docs/architecture.md).
using EffectTerms = std::tuple<ViscousTerm, ForceDelayTerm, BacklashTerm, LoadFrictionTerm, LoadCellOffsetTerm>;

// The first parameter of any term that breaks its bound.
inline TermViolation check_effect_terms(const EffectTermValues& v) {
  TermViolation out;
  std::apply([&](auto... term) { ((out = out ? out : decltype(term)::check(v)), ...); }, EffectTerms{});
  return out;
}

// Regressor columns the terms add to the calibrator's fit (beyond the curve and the elements).
inline int effect_columns(const EffectTermValues& v) {
  return std::apply([&](auto... term) { return (decltype(term)::columns(v) + ...); }, EffectTerms{});
}

}  // namespace bbw::model

// The names where they lived before model/ existed (bbw::calibration), so code written against them
// keeps compiling; new code says bbw::model.
namespace bbw::calibration {
using model::EffectTermValues;
using model::TermBound;
using model::kNoUpperBound;
using model::TermViolation;
using model::ViscousTerm;
using model::ForceDelayTerm;
using model::BacklashTerm;
using model::LoadFrictionTerm;
using model::LoadCellOffsetTerm;
using model::EffectTerms;
using model::check_effect_terms;
using model::effect_columns;
}  // namespace bbw::calibration
