#include "bbw/analyze/config_loader.hpp"

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/common/data_path.hpp"

#include <cmath>
#include <stdexcept>

namespace bbw::analyze {

using config::Range;

analysis::AnalysisOptions load_options(config::Reader& r) {
  analysis::AnalysisOptions o;
  if (auto m = r.optional_map("baseline")) {
    if (m->has("curve_knots_grid")) {
      o.curve_knots_grid.clear();
      for (double k : m->numbers("curve_knots_grid", Range::closed(0, 30))) {
        if (k != std::floor(k)) m->fail("curve_knots_grid", "entries must be whole numbers");
        o.curve_knots_grid.push_back(static_cast<int>(k));
      }
    }
    o.curve_knots_tolerance = m->number_or("curve_knots_tolerance", o.curve_knots_tolerance, Range{0.0, 1.0, false, true});
    o.elements_M = static_cast<int>(m->integer_or("elements_M", o.elements_M, 1, 64));
    o.geometric_ratio = m->number_or("geometric_ratio", o.geometric_ratio, Range{0.0, 1.0, true, false});
    if (m->has("delta_max_fractions")) o.delta_max_fractions = m->numbers("delta_max_fractions", Range::positive());
    m->finish();
  }
  if (auto m = r.optional_map("holdout")) {
    o.split = m->choice_or("split", "interleaved", {"interleaved", "tail"}) == "tail" ? analysis::HoldoutSplit::Tail
                                                                                      : analysis::HoldoutSplit::Interleaved;
    o.holdout_fraction = m->number_or("fraction", o.holdout_fraction, Range::closed(0.1, 0.5));
    o.split_blocks = static_cast<int>(m->integer_or("blocks", o.split_blocks, 3, 1000));
    m->finish();
  }
  if (auto m = r.optional_map("differentiator")) {
    o.velocity_window_s = m->number_or("velocity_window_s", o.velocity_window_s, Range::positive());
    o.acceleration_window_s = m->number_or("acceleration_window_s", o.acceleration_window_s, Range::positive());
    m->finish();
  }
  if (auto m = r.optional_map("acceptance")) {
    o.min_relative_drop = m->number_or("min_relative_drop", o.min_relative_drop, Range{0.0, 1.0, false, true});
    o.min_t_statistic = m->number_or("min_t_statistic", o.min_t_statistic, Range::non_negative());
    o.significance_blocks = static_cast<int>(m->integer_or("significance_blocks", o.significance_blocks, 5, 10000));
    o.max_steps = static_cast<int>(m->integer_or("max_steps", o.max_steps, 0, 20));
    m->finish();
  }
  if (auto m = r.optional_map("search")) {
    if (m->has("delay_grid_s")) o.delay_grid_s = m->numbers("delay_grid_s");
    if (m->has("backlash_width_fractions"))
      o.backlash_width_fractions = m->numbers("backlash_width_fractions", Range::positive());
    if (m->has("creep_tau_s")) o.creep_tau_s = m->numbers("creep_tau_s", Range::positive());
    o.search_max_rows = static_cast<int>(m->integer_or("max_rows", o.search_max_rows, 1000, 100000000));
    m->finish();
  }
  if (auto m = r.optional_map("effects")) {
    std::vector<std::string> tried, sensor;
    for (const auto& name : analysis::named_effects()) {
      const bool was_tried = o.is_candidate(name);
      const bool was_sensor = o.is_sensor_effect(name);
      bool t = was_tried, s = was_sensor;
      if (auto e = m->optional_map(name)) {
        t = e->boolean_or("try", was_tried);
        s = e->boolean_or("sensor", was_sensor);
        e->finish();
      }
      if (t) tried.push_back(name);
      if (s) sensor.push_back(name);
    }
    o.candidates = tried;
    o.sensor_effects = sensor;
    m->finish();
  }
  if (r.has("temperature_reference_C"))
    o.temperature_reference_C = r.number("temperature_reference_C", Range::closed(-60.0, 200.0));
  if (auto m = r.optional_map("structure")) {
    o.ljung_box_lags = static_cast<int>(m->integer_or("ljung_box_lags", o.ljung_box_lags, 1, 1000));
    o.structure_bins = static_cast<int>(m->integer_or("bins", o.structure_bins, 2, 1000));
    o.structure_min_eta2 = m->number_or("min_eta2", o.structure_min_eta2, Range{0.0, 1.0, true, true});
    o.structure_min_signal_to_noise =
        m->number_or("min_signal_to_noise", o.structure_min_signal_to_noise, Range::positive());
    m->finish();
  }
  r.finish();
  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    r.fail("", e.what());
  }
  return o;
}

analysis::AnalysisOptions load_options_file(const std::string& file) {
  auto r = config::Reader::from_file(file);
  return load_options(r);
}

std::vector<double> calibrator_friction_thresholds(const std::string& calibrator_file, const std::string& position_unit) {
  if (calibrator_file == "none") return {};
  if (calibrator_file.empty() && position_unit != "rev") return {};
  const std::string file = calibrator_file.empty() ? data::path("config/calibrator/robust.yaml") : calibrator_file;
  return calibration::friction_thresholds_rev(calibration::load_config(file));
}

}  // namespace bbw::analyze
