#include "bbw/calibration/config_yaml.hpp"

#include <cstdio>
#include <stdexcept>
#include <string>

namespace bbw::calibration {

using bbw::config::Range;
using bbw::config::Reader;

CalibratorConfig read_config(Reader& r) {
  CalibratorConfig c;
  c.mode = r.choice("mode", {"paper", "robust"}) == "paper" ? Mode::Paper : Mode::Robust;
  c.elements_M = static_cast<int>(r.integer("elements_M", 1, 64));
  c.samples_L = static_cast<int>(r.integer("samples_L", 2, 4096));
  c.pf_points_N = static_cast<int>(r.integer("pf_points_N", 3, 1000));
  c.start_lag_n0 = static_cast<int>(r.integer("start_lag_n0", 1, 10000));
  c.delta_max_rev = r.number("delta_max_rev", Range::positive());
  auto range = r.map("range");
  c.x_min_rev = range.number("x_min_rev");
  c.x_max_rev = range.number("x_max_rev");
  c.f_min_kN = range.number("f_min_kN");
  c.f_max_kN = range.number("f_max_kN");
  c.full_scale_kN = range.number_or("full_scale_kN", 40.0, Range::positive());
  range.finish();
  if (!(c.x_max_rev > c.x_min_rev)) range.fail("x_max_rev", "must be > range.x_min_rev");
  if (!(c.f_max_kN > c.f_min_kN)) range.fail("f_max_kN", "must be > range.f_min_kN");

  auto curve = r.map("initial_curve");
  c.initial_curve.a = curve.number("a_kN_per_rev3");
  c.initial_curve.b = curve.number("b_kN_per_rev2");
  c.initial_curve.c = curve.number("c_kN_per_rev");
  c.initial_curve.d = curve.number("d_kN");
  curve.finish();

  if (auto acc = r.optional_map("accept")) {
    c.accept_position_min_rev = acc->number_or("position_min_rev", c.accept_position_min_rev);
    c.accept_position_max_rev = acc->number_or("position_max_rev", c.accept_position_max_rev);
    c.accept_force_min_kN = acc->number_or("force_min_kN", c.accept_force_min_kN);
    c.accept_force_max_kN = acc->number_or("force_max_kN", c.accept_force_max_kN);
    acc->finish();
    if (!(c.accept_position_max_rev > c.accept_position_min_rev)) acc->fail("position_max_rev", "must be > position_min_rev");
    if (!(c.accept_force_max_kN > c.accept_force_min_kN)) acc->fail("force_max_kN", "must be > force_min_kN");
  }
  c.drop_rule = r.choice_or("drop_rule", "j", {"j", "j_plus_1"}) == "j" ? DropRule::DropJ : DropRule::DropJPlus1;

  if (auto rb = r.optional_map("robust")) {
    c.scale_x = rb->boolean_or("scale_x", c.scale_x);
    c.nonnegative_k = rb->boolean_or("nonnegative_k", c.nonnegative_k);
    c.min_cycle_span_rev = rb->number_or("min_cycle_span_rev", c.min_cycle_span_rev, Range::non_negative());
    c.spacing = rb->choice_or("spacing", c.spacing == ThresholdSpacing::Geometric ? "geometric" : "even",
                              {"even", "geometric"}) == "geometric"
                    ? ThresholdSpacing::Geometric
                    : ThresholdSpacing::Even;
    c.geometric_ratio = rb->number_or("geometric_ratio", c.geometric_ratio, Range{0.0, 1.0, true, true});
    c.streaming_states = rb->boolean_or("streaming_states", c.streaming_states);
    c.ridge = rb->number_or("ridge", c.ridge, Range::non_negative());
    c.max_fit_rms_kN = rb->number_or("max_fit_rms_kN", c.max_fit_rms_kN, Range::positive());
    c.start_margin_rev = rb->number_or("start_margin_rev", c.start_margin_rev, Range::non_negative());
    c.k_smoothing = rb->number_or("k_smoothing", c.k_smoothing, Range{0.0, 1.0, true, false});
    c.identify_per_element = rb->boolean_or("identify_per_element", c.identify_per_element);
    c.friction_memory = rb->number_or("friction_memory", c.friction_memory, Range{0.0, 1.0, false, false});
    c.residual_window = static_cast<int>(
        rb->integer_or("residual_window", c.residual_window, 1, CalibratorConfig::kMaxResidualWindow));
    rb->finish();
  }
  if (auto fx = r.optional_map("effects")) {
    c.viscous_friction = fx->boolean_or(ViscousTerm::key, c.viscous_friction);
    // Bounds from the term objects (bbw/model/effect_terms.hpp), the one copy.
    auto number = [&fx](const TermBound& b, double fallback) {
      return fx->number_or(b.key, fallback, Range{b.min, b.max, b.min_open, false});
    };
    c.viscous_speed_scale_rev_per_s = number(ViscousTerm::speed_scale, c.viscous_speed_scale_rev_per_s);
    c.velocity_window = static_cast<int>(fx->integer_or("velocity_window", c.velocity_window, 2, 1000));
    c.force_delay_s = number(ForceDelayTerm::delay, c.force_delay_s);
    c.load_friction_gain = number(LoadFrictionTerm::gain, c.load_friction_gain);
    c.load_friction_reference_kN = number(LoadFrictionTerm::reference, c.load_friction_reference_kN);
    c.backlash_width_rev = number(BacklashTerm::width, c.backlash_width_rev);
    c.load_cell_offset_kN_per_C = number(LoadCellOffsetTerm::slope, c.load_cell_offset_kN_per_C);
    c.load_cell_offset_reference_C = number(LoadCellOffsetTerm::reference, c.load_cell_offset_reference_C);
    fx->finish();
  }
  if (auto fr = r.optional_map("initial_friction")) {
    c.initial_stiffness_kN_per_rev = fr->numbers("stiffness_kN_per_rev", Range::non_negative());
    c.initial_viscous_kN_per_rev_per_s = fr->number_or("viscous_kN_per_rev_per_s", 0.0, Range::non_negative());
    c.initial_friction_weight = fr->number("weight", Range::non_negative());
    fr->finish();
    if (c.initial_stiffness_kN_per_rev.size() != static_cast<std::size_t>(c.elements_M)) {
      fr->fail("stiffness_kN_per_rev", "must hold elements_M = " + std::to_string(c.elements_M) + " values, not " +
                                           std::to_string(c.initial_stiffness_kN_per_rev.size()));
    }
  }
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    r.fail("", e.what());
  }
  return c;
}

std::string to_yaml(const CalibratorConfig& c) {
  std::string out;
  char line[160];
  auto put = [&](const char* fmt, auto... v) {
    std::snprintf(line, sizeof line, fmt, v...);
    out += line;
  };
  auto yes = [](bool b) { return b ? "true" : "false"; };
  put("mode: %s\n", to_string(c.mode));
  put("elements_M: %d\nsamples_L: %d\npf_points_N: %d\nstart_lag_n0: %d\n", c.elements_M, c.samples_L, c.pf_points_N,
      c.start_lag_n0);
  put("delta_max_rev: %.17g\n", c.delta_max_rev);
  put("range:\n  x_min_rev: %.17g\n  x_max_rev: %.17g\n", c.x_min_rev, c.x_max_rev);
  put("  f_min_kN: %.17g\n  f_max_kN: %.17g\n  full_scale_kN: %.17g\n", c.f_min_kN, c.f_max_kN, c.full_scale_kN);
  put("initial_curve:\n  a_kN_per_rev3: %.17g\n  b_kN_per_rev2: %.17g\n", c.initial_curve.a, c.initial_curve.b);
  put("  c_kN_per_rev: %.17g\n  d_kN: %.17g\n", c.initial_curve.c, c.initial_curve.d);
  put("accept:\n  position_min_rev: %.17g\n  position_max_rev: %.17g\n", c.accept_position_min_rev,
      c.accept_position_max_rev);
  put("  force_min_kN: %.17g\n  force_max_kN: %.17g\n", c.accept_force_min_kN, c.accept_force_max_kN);
  put("drop_rule: %s\n", c.drop_rule == DropRule::DropJ ? "j" : "j_plus_1");
  put("robust:\n  scale_x: %s\n  nonnegative_k: %s\n", yes(c.scale_x), yes(c.nonnegative_k));
  put("  min_cycle_span_rev: %.17g\n", c.min_cycle_span_rev);
  put("  spacing: %s\n", c.spacing == ThresholdSpacing::Geometric ? "geometric" : "even");
  put("  geometric_ratio: %.17g\n  streaming_states: %s\n", c.geometric_ratio, yes(c.streaming_states));
  put("  ridge: %.17g\n  max_fit_rms_kN: %.17g\n", c.ridge, c.max_fit_rms_kN);
  put("  start_margin_rev: %.17g\n  k_smoothing: %.17g\n", c.start_margin_rev, c.k_smoothing);
  put("  identify_per_element: %s\n  friction_memory: %.17g\n", yes(c.identify_per_element), c.friction_memory);
  put("  residual_window: %d\n", c.residual_window);
  put("effects:\n  %s: %s\n", ViscousTerm::key, yes(c.viscous_friction));
  put("  %s: %.17g\n", ViscousTerm::speed_scale.key, c.viscous_speed_scale_rev_per_s);
  put("  velocity_window: %d\n", c.velocity_window);
  put("  %s: %.17g\n", ForceDelayTerm::delay.key, c.force_delay_s);
  put("  %s: %.17g\n", LoadFrictionTerm::gain.key, c.load_friction_gain);
  put("  %s: %.17g\n", LoadFrictionTerm::reference.key, c.load_friction_reference_kN);
  put("  %s: %.17g\n", BacklashTerm::width.key, c.backlash_width_rev);
  put("  %s: %.17g\n", LoadCellOffsetTerm::slope.key, c.load_cell_offset_kN_per_C);
  put("  %s: %.17g\n", LoadCellOffsetTerm::reference.key, c.load_cell_offset_reference_C);
  if (!c.initial_stiffness_kN_per_rev.empty()) {
    out += "initial_friction:\n  stiffness_kN_per_rev: [";
    for (std::size_t i = 0; i < c.initial_stiffness_kN_per_rev.size(); ++i) {
      put(i == 0 ? "%.17g" : ", %.17g", c.initial_stiffness_kN_per_rev[i]);
    }
    put("]\n  viscous_kN_per_rev_per_s: %.17g\n  weight: %.17g\n", c.initial_viscous_kN_per_rev_per_s,
        c.initial_friction_weight);
  }
  return out;
}

CalibratorConfig load_config(const std::string& file) {
  Reader r = Reader::from_file(file);
  CalibratorConfig c = read_config(r);
  r.finish();
  return c;
}

}  // namespace bbw::calibration
