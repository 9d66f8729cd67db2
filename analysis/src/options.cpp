#include "bbw/analysis/options.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace bbw::analysis {

const char* to_string(EffectKind k) {
  switch (k) {
    case EffectKind::ViscousFriction: return "viscous_friction";
    case EffectKind::LoadDependentFriction: return "load_dependent_friction";
    case EffectKind::SensorDelay: return "sensor_delay";
    case EffectKind::TemperatureDrift: return "temperature_drift";
    case EffectKind::Backlash: return "backlash";
    case EffectKind::Creep: return "creep";
    case EffectKind::Inertia: return "inertia";
    case EffectKind::Channel: return "channel";
    case EffectKind::ChannelTimesVelocity: return "channel_x_velocity";
  }
  return "?";
}

const std::vector<std::string>& named_effects() {
  static const std::vector<std::string> names = {"viscous_friction", "load_dependent_friction", "sensor_delay",
                                                 "temperature_drift", "backlash", "creep", "inertia"};
  return names;
}

namespace {

template <typename T>
[[noreturn]] void bad(const std::string& field, const T& value, const std::string& rule) {
  std::ostringstream o;
  o << "AnalysisOptions." << field << " = " << value << ": " << rule;
  throw std::invalid_argument(o.str());
}

void positive_grid(const std::string& field, const std::vector<double>& v, bool allow_negative) {
  if (v.empty()) bad(field, "[]", "must not be empty");
  for (double x : v) {
    if (!std::isfinite(x) || (!allow_negative && x <= 0.0) || x == 0.0)
      bad(field, x, allow_negative ? "entries must be finite and non-zero" : "entries must be > 0");
  }
}

void known_names(const std::string& field, const std::vector<std::string>& v) {
  for (const auto& s : v) {
    const auto& n = named_effects();
    if (std::find(n.begin(), n.end(), s) == n.end()) bad(field, s, "unknown effect name");
  }
}

}  // namespace

void AnalysisOptions::validate() const {
  if (curve_knots_grid.empty()) bad("curve_knots_grid", "[]", "must not be empty");
  for (std::size_t i = 0; i < curve_knots_grid.size(); ++i) {
    const int k = curve_knots_grid[i];
    if (k < 0 || k > 30) bad("curve_knots_grid", k, "entries must be in [0, 30]");
    if (i > 0 && k <= curve_knots_grid[i - 1]) bad("curve_knots_grid", k, "entries must be increasing");
  }
  if (!(curve_knots_tolerance >= 0.0 && curve_knots_tolerance < 1.0))
    bad("curve_knots_tolerance", curve_knots_tolerance, "must be in [0, 1)");
  if (friction_thresholds.size() > 64) bad("friction_thresholds", static_cast<double>(friction_thresholds.size()), "at most 64 elements");
  for (std::size_t i = 0; i < friction_thresholds.size(); ++i) {
    const double d = friction_thresholds[i];
    if (!(d > 0.0) || !std::isfinite(d) || (i > 0 && !(d > friction_thresholds[i - 1])))
      bad("friction_thresholds", d, "must be finite, > 0 and increasing");
  }
  if (elements_M < 1 || elements_M > 64) bad("elements_M", elements_M, "must be in [1, 64]");
  if (!(geometric_ratio > 0.0 && geometric_ratio <= 1.0)) bad("geometric_ratio", geometric_ratio, "must be in (0, 1]");
  positive_grid("delta_max_fractions", delta_max_fractions, false);
  if (!(holdout_fraction >= 0.1 && holdout_fraction <= 0.5)) bad("holdout_fraction", holdout_fraction, "must be in [0.1, 0.5]");
  if (split_blocks < 3 || split_blocks > 1000) bad("split_blocks", split_blocks, "must be in [3, 1000]");
  if (!(velocity_window_s > 0.0)) bad("velocity_window_s", velocity_window_s, "must be > 0");
  if (!(acceleration_window_s > 0.0)) bad("acceleration_window_s", acceleration_window_s, "must be > 0");
  if (!(min_relative_drop >= 0.0 && min_relative_drop < 1.0)) bad("min_relative_drop", min_relative_drop, "must be in [0, 1)");
  if (!(min_t_statistic >= 0.0)) bad("min_t_statistic", min_t_statistic, "must be >= 0");
  if (significance_blocks < 5) bad("significance_blocks", significance_blocks, "must be >= 5");
  if (max_steps < 0 || max_steps > 20) bad("max_steps", max_steps, "must be in [0, 20]");
  positive_grid("delay_grid_s", delay_grid_s, true);
  positive_grid("backlash_width_fractions", backlash_width_fractions, false);
  positive_grid("creep_tau_s", creep_tau_s, false);
  if (search_max_rows < 1000) bad("search_max_rows", search_max_rows, "must be >= 1000");
  known_names("candidates", candidates);
  known_names("sensor_effects", sensor_effects);
  if (ljung_box_lags < 1 || ljung_box_lags > 1000) bad("ljung_box_lags", ljung_box_lags, "must be in [1, 1000]");
  if (structure_bins < 2 || structure_bins > 1000) bad("structure_bins", structure_bins, "must be in [2, 1000]");
  if (!(structure_min_eta2 > 0.0 && structure_min_eta2 < 1.0)) bad("structure_min_eta2", structure_min_eta2, "must be in (0, 1)");
  if (!(structure_min_signal_to_noise > 0.0)) bad("structure_min_signal_to_noise", structure_min_signal_to_noise, "must be > 0");
}

bool AnalysisOptions::is_candidate(const std::string& name) const {
  return std::find(candidates.begin(), candidates.end(), name) != candidates.end();
}

bool AnalysisOptions::is_sensor_effect(const std::string& name) const {
  return std::find(sensor_effects.begin(), sensor_effects.end(), name) != sensor_effects.end();
}

}  // namespace bbw::analysis
