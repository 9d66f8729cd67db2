#include "bbw/calibration/config.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "bbw/model/maxwell_slip.hpp"

namespace bbw::calibration {

namespace {

[[noreturn]] void bad(const char* field, double value, const char* rule) {
  std::ostringstream os;
  os << "calibrator config: " << field << " = " << value << ": " << rule;
  throw std::invalid_argument(os.str());
}

// A term bound as a rule: "must be in [0, 0.5]", "must be > 0", ...
std::string rule_of(const TermBound& b) {
  std::ostringstream os;
  if (b.max == kNoUpperBound) {
    os << "must be " << (b.min_open ? "> " : ">= ") << b.min;
  } else {
    os << "must be in " << (b.min_open ? "(" : "[") << b.min << ", " << b.max << "]";
  }
  return os.str();
}

}  // namespace

EffectTermValues CalibratorConfig::effect_values() const {
  EffectTermValues v;
  v.viscous = viscous_friction;
  v.viscous_speed_scale_rev_per_s = viscous_speed_scale_rev_per_s;
  v.force_delay_s = force_delay_s;
  v.backlash_width_rev = backlash_width_rev;
  v.load_friction_gain = load_friction_gain;
  v.load_friction_reference_kN = load_friction_reference_kN;
  v.load_cell_offset_kN_per_C = load_cell_offset_kN_per_C;
  v.load_cell_offset_reference_C = load_cell_offset_reference_C;
  return v;
}

const char* to_string(Mode m) { return m == Mode::Paper ? "paper" : "robust"; }

std::vector<double> friction_thresholds_rev(const CalibratorConfig& config) {
  const auto m = static_cast<std::size_t>(config.elements_M > 0 ? config.elements_M : 0);
  std::vector<double> out(m, 0.0);
  const bool geometric = config.mode == Mode::Robust && config.spacing == ThresholdSpacing::Geometric;
  thresholds(m, config.delta_max_rev, geometric, config.geometric_ratio, out.data());
  return out;
}

void CalibratorConfig::validate() const {
  if (elements_M < 1 || elements_M > 64) bad("elements_M", elements_M, "must be in [1, 64]");
  if (samples_L < 2 * (4 + elements_M) || samples_L > 4096) {
    bad("samples_L", samples_L, "must be in [2 (4 + elements_M), 4096]");
  }
  if (pf_points_N < 3 || pf_points_N > 1000) bad("pf_points_N", pf_points_N, "must be in [3, 1000]");
  if (start_lag_n0 < 1 || start_lag_n0 > 10000) bad("start_lag_n0", start_lag_n0, "must be in [1, 10000]");
  if (!(delta_max_rev > 0.0) || !std::isfinite(delta_max_rev)) bad("delta_max_rev", delta_max_rev, "must be > 0");
  if (!(x_max_rev > x_min_rev)) bad("x_max_rev", x_max_rev, "must be > x_min_rev");
  if (!(f_max_kN > f_min_kN)) bad("f_max_kN", f_max_kN, "must be > f_min_kN");
  if (!(full_scale_kN > 0.0)) bad("full_scale_kN", full_scale_kN, "must be > 0");
  if (!(accept_position_max_rev > accept_position_min_rev)) {
    bad("accept_position_max_rev", accept_position_max_rev, "must be > accept_position_min_rev");
  }
  if (!(accept_force_max_kN > accept_force_min_kN)) bad("accept_force_max_kN", accept_force_max_kN, "must be > accept_force_min_kN");
  if (!std::isfinite(initial_curve.a) || !std::isfinite(initial_curve.b) || !std::isfinite(initial_curve.c) ||
      !std::isfinite(initial_curve.d)) {
    bad("initial_curve", 0.0, "coefficients must be finite");
  }
  if (!(min_cycle_span_rev >= 0.0)) bad("min_cycle_span_rev", min_cycle_span_rev, "must be >= 0");
  if (!(geometric_ratio > 0.0 && geometric_ratio < 1.0)) bad("geometric_ratio", geometric_ratio, "must be in (0, 1)");
  if (!(ridge >= 0.0)) bad("ridge", ridge, "must be >= 0");
  if (!(friction_memory >= 0.0 && friction_memory <= 1.0)) bad("friction_memory", friction_memory, "must be in [0, 1]");
  if (!(max_fit_rms_kN > 0.0)) bad("max_fit_rms_kN", max_fit_rms_kN, "must be > 0");
  if (!(start_margin_rev >= 0.0)) bad("start_margin_rev", start_margin_rev, "must be >= 0");
  if (!initial_stiffness_kN_per_rev.empty() &&
      initial_stiffness_kN_per_rev.size() != static_cast<std::size_t>(elements_M)) {
    bad("initial_friction.stiffness_kN_per_rev", static_cast<double>(initial_stiffness_kN_per_rev.size()),
        "must hold elements_M values (entries given)");
  }
  for (double k : initial_stiffness_kN_per_rev) {
    if (!(k >= 0.0) || !std::isfinite(k)) bad("initial_friction.stiffness_kN_per_rev", k, "must be finite and >= 0");
  }
  if (!(initial_viscous_kN_per_rev_per_s >= 0.0) || !std::isfinite(initial_viscous_kN_per_rev_per_s)) {
    bad("initial_friction.viscous_kN_per_rev_per_s", initial_viscous_kN_per_rev_per_s, "must be finite and >= 0");
  }
  if (!(initial_friction_weight >= 0.0) || !std::isfinite(initial_friction_weight)) {
    bad("initial_friction.weight", initial_friction_weight, "must be finite and >= 0");
  }
  if (velocity_window < 2 || velocity_window > 1000) bad("velocity_window", velocity_window, "must be in [2, 1000]");
  if (const auto e = check_effect_terms(effect_values())) bad(e.bound->key, e.value, rule_of(*e.bound).c_str());
  if (!(k_smoothing > 0.0 && k_smoothing <= 1.0)) bad("k_smoothing", k_smoothing, "must be in (0, 1]");
  if (residual_window < 1 || residual_window > kMaxResidualWindow) {
    bad("residual_window", residual_window, "must be in [1, 64]");
  }
}

}  // namespace bbw::calibration
