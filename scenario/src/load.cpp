#include "bbw/scenario/load.hpp"

#include <algorithm>
#include <limits>
#include <set>
#include <stdexcept>

#include "bbw/plant/params_yaml.hpp"
#include "bbw/scenario/population.hpp"

namespace bbw::scenario {

using config::ConfigError;
using config::Range;
using config::Reader;

namespace {

int line_of(const YAML::Node& n) { return n.IsDefined() && n.Mark().line >= 0 ? n.Mark().line + 1 : 0; }

std::string child(const Reader& r, const std::string& key) {
  return r.path().empty() ? key : r.path() + "." + key;
}

// Reader::finish() for mappings holding a key read straight from the YAML node (a list of
// [t, value] pairs): rejects every key not in `allowed`.
void finish_with(const Reader& r, const std::set<std::string>& allowed) {
  for (const auto& kv : r.node()) {
    const std::string k = kv.first.Scalar();
    if (allowed.count(k) == 0) throw ConfigError(r.file(), line_of(kv.first), child(r, k), "unknown key");
  }
}

// A required list of [t_s, value] pairs with strictly increasing times and values in `range`.
std::vector<Breakpoint> read_breakpoints(const Reader& r, const std::string& key, const Range& range) {
  const YAML::Node n = r.node()[key];
  if (!n.IsDefined() || n.IsNull()) r.fail(key, "required key is missing");
  if (!n.IsSequence() || n.size() == 0) r.fail(key, "must be a non-empty list of [t_s, value] pairs");
  std::vector<Breakpoint> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node item = n[i];
    const std::string path = child(r, key + "[" + std::to_string(i) + "]");
    if (!item.IsSequence() || item.size() != 2 || !item[0].IsScalar() || !item[1].IsScalar()) {
      throw ConfigError(r.file(), line_of(item), path, "must be a pair [t_s, value]");
    }
    Breakpoint b;
    try {
      b.t_s = item[0].as<double>();
      b.value = item[1].as<double>();
    } catch (const YAML::Exception&) {
      throw ConfigError(r.file(), line_of(item), path, "must be a pair of numbers [t_s, value]");
    }
    if (!Range::non_negative().contains(b.t_s)) {
      throw ConfigError(r.file(), line_of(item), path, "time must be a finite number >= 0");
    }
    if (!range.contains(b.value)) throw ConfigError(r.file(), line_of(item), path, "value " + range.describe());
    if (!out.empty() && !(b.t_s > out.back().t_s)) {
      throw ConfigError(r.file(), line_of(item), path, "times must increase strictly");
    }
    out.push_back(b);
  }
  return out;
}

int count(Reader& r, const std::string& key, int fallback) {
  return static_cast<int>(r.integer_or(key, fallback, 1, 100000));
}

PositionSegment read_segment(Reader& s) {
  const std::string type = s.choice("type", {"paper_sweep", "local_loops", "sine", "steps", "hold"});
  const Range pos = Range::closed(-2.0, 12.0);
  PositionSegment out;
  if (type == "paper_sweep") {
    PaperSweep p;
    p.x_low_rev = s.number("x_low_rev", pos);
    p.amplitudes_rev = s.numbers("amplitudes_rev", Range{0.0, 12.0, true, false});
    if (p.amplitudes_rev.empty()) s.fail("amplitudes_rev", "must not be empty");
    p.period_s = s.number("period_s", Range::closed(0.01, 1000.0));
    p.cycles_per_amplitude = count(s, "cycles_per_amplitude", 1);
    out = p;
  } else if (type == "local_loops") {
    LocalLoops l;
    l.levels_rev = s.numbers("levels_rev", pos);
    if (l.levels_rev.empty()) s.fail("levels_rev", "must not be empty");
    l.amplitude_rev = s.number("amplitude_rev", Range{0.0, 5.0, true, false});
    l.period_s = s.number("period_s", Range::closed(0.01, 1000.0));
    l.cycles_per_level = count(s, "cycles_per_level", 2);
    l.ramp_s = s.number_or("ramp_s", 1.0, Range::closed(0.01, 1000.0));
    out = l;
  } else if (type == "sine") {
    Sine w;
    w.offset_rev = s.number("offset_rev", pos);
    w.amplitude_rev = s.number("amplitude_rev", Range{0.0, 10.0, true, false});
    w.period_s = s.number("period_s", Range::closed(0.01, 1000.0));
    w.cycles = count(s, "cycles", 1);
    out = w;
  } else if (type == "steps") {
    Steps st;
    st.levels_rev = s.numbers("levels_rev", pos);
    if (st.levels_rev.empty()) s.fail("levels_rev", "must not be empty");
    st.hold_s = s.number("hold_s", Range::closed(0.001, 1000.0));
    out = st;
  } else {
    Hold h;
    h.position_rev = s.number("position_rev", pos);
    h.duration_s = s.number("duration_s", Range::closed(0.001, 100000.0));
    out = h;
  }
  s.finish();
  return out;
}

corner_unit::ForceFeedback read_feedback(Reader& d) {
  const std::string f = d.choice_or("feedback", "load_cell", {"load_cell", "compensated", "curve", "true"});
  if (f == "compensated") return corner_unit::ForceFeedback::Compensated;
  if (f == "curve") return corner_unit::ForceFeedback::Curve;
  if (f == "true") return corner_unit::ForceFeedback::True;
  return corner_unit::ForceFeedback::LoadCell;
}

DriveSpec read_drive(Reader& d) {
  DriveSpec drive;
  const std::string mode = d.choice("mode", {"position", "force", "demand"});
  if (mode == "position") {
    drive.mode = DriveMode::Position;
    drive.position.start_rev = d.number_or("start_rev", 0.0, Range::closed(-2.0, 12.0));
    drive.position.ramp_s = d.number_or("ramp_s", 1.0, Range::closed(0.01, 1000.0));
    for (Reader& s : d.maps("segments")) drive.position.segments.push_back(read_segment(s));
    if (drive.position.segments.empty()) d.fail("segments", "must list at least one segment");
    d.finish();
    try {
      PositionProfile check(drive.position);
    } catch (const std::invalid_argument& e) {
      d.fail("segments", e.what());
    }
  } else if (mode == "force") {
    drive.mode = DriveMode::Force;
    drive.feedback = read_feedback(d);
    drive.force_kN = read_breakpoints(d, "breakpoints", Range::closed(0.0, 100.0));
    finish_with(d, {"mode", "feedback", "breakpoints"});
  } else {
    drive.mode = DriveMode::Demand;
    drive.feedback = read_feedback(d);
    d.finish();
  }
  return drive;
}

corner_unit::ControllerParams read_controller(Reader& c) {
  corner_unit::ControllerParams p;
  p.position_gain_per_s = c.number_or("position_gain_per_s", p.position_gain_per_s, Range::positive());
  p.speed_gain_A_per_rev_per_s =
      c.number_or("speed_gain_A_per_rev_per_s", p.speed_gain_A_per_rev_per_s, Range::positive());
  p.speed_integral_gain_A_per_rev =
      c.number_or("speed_integral_gain_A_per_rev", p.speed_integral_gain_A_per_rev, Range::non_negative());
  p.max_speed_rev_per_s = c.number_or("max_speed_rev_per_s", p.max_speed_rev_per_s, Range::positive());
  p.force_bandwidth_rad_per_s =
      c.number_or("force_bandwidth_rad_per_s", p.force_bandwidth_rad_per_s, Range::positive());
  p.force_integral_rad_per_s2 =
      c.number_or("force_integral_rad_per_s2", p.force_integral_rad_per_s2, Range::non_negative());
  p.force_integral_max_speed_error_rev_per_s = c.number_or(
      "force_integral_max_speed_error_rev_per_s", p.force_integral_max_speed_error_rev_per_s, Range::non_negative());
  p.stiffness_at_zero_kN_per_rev =
      c.number_or("stiffness_at_zero_kN_per_rev", p.stiffness_at_zero_kN_per_rev, Range::positive());
  p.stiffness_per_kN_per_rev =
      c.number_or("stiffness_per_kN_per_rev", p.stiffness_per_kN_per_rev, Range::non_negative());
  p.release_force_kN = c.number_or("release_force_kN", p.release_force_kN, Range::closed(0.0, 10.0));
  p.release_position_rev = c.number_or("release_position_rev", p.release_position_rev, Range::closed(-2.0, 12.0));
  p.load_feedforward = c.boolean_or("load_feedforward", p.load_feedforward);
  p.force_home_limit = c.boolean_or("force_home_limit", p.force_home_limit);
  p.feedback_switch_restart = c.boolean_or("feedback_switch_restart", p.feedback_switch_restart);
  p.force_home_margin_rev = c.number_or("force_home_margin_rev", p.force_home_margin_rev, Range::closed(0.0, 2.0));
  p.curve_trusted_min_rev = c.number_or("curve_trusted_min_rev", p.curve_trusted_min_rev, Range::closed(-2.0, 12.0));
  p.stiffness_estimate = c.boolean_or("stiffness_estimate", p.stiffness_estimate);
  p.stiffness_stride_rev = c.number_or("stiffness_stride_rev", p.stiffness_stride_rev, Range::positive());
  p.stiffness_stride_kN = c.number_or("stiffness_stride_kN", p.stiffness_stride_kN, Range::positive());
  p.stiffness_memory_rev = c.number_or("stiffness_memory_rev", p.stiffness_memory_rev, Range::positive());
  p.stiffness_reversal_rev = c.number_or("stiffness_reversal_rev", p.stiffness_reversal_rev, Range::non_negative());
  p.stiffness_hold_rev = c.number_or("stiffness_hold_rev", p.stiffness_hold_rev, Range::positive());
  p.stiffness_max_ratio = c.number_or("stiffness_max_ratio", p.stiffness_max_ratio, Range::closed(1.0, 1.0e4));
  p.frozen_resolver_samples = static_cast<int>(c.integer_or("frozen_resolver_samples", p.frozen_resolver_samples, 0, 100000));
  p.hold_test_current_A = c.number_or("hold_test_current_A", p.hold_test_current_A, Range::closed(0.0, 10.0));
  p.hold_test_pulse_s = c.number_or("hold_test_pulse_s", p.hold_test_pulse_s, Range::closed(0.0005, 0.007));
  p.hold_test_period_s = c.number_or("hold_test_period_s", p.hold_test_period_s, Range::closed(0.01, 10.0));
  p.hold_test_min_hold_s = c.number_or("hold_test_min_hold_s", p.hold_test_min_hold_s, Range::closed(0.0, 10.0));
  p.hold_test_min_force_kN = c.number_or("hold_test_min_force_kN", p.hold_test_min_force_kN, Range::closed(0.0, 100.0));
  p.hold_test_max_speed_rev_per_s =
      c.number_or("hold_test_max_speed_rev_per_s", p.hold_test_max_speed_rev_per_s, Range::positive());
  p.hold_test_max_error_kN = c.number_or("hold_test_max_error_kN", p.hold_test_max_error_kN, Range::positive());
  c.finish();
  return p;
}

CornerSpec read_corner(Reader& c, const Scenario& sc) {
  CornerSpec k;
  k.line = c.line();
  k.name = c.string("name");
  // The name becomes part of file names (DIR/<name>.csv, corner_<name>.stats): no path tricks.
  const bool plain = !k.name.empty() && k.name.size() <= 32 &&
                     k.name.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-") ==
                         std::string::npos;
  if (!plain) c.fail("name", "must be 1 to 32 letters, digits, '_' or '-'");
  if (c.has("axle")) {
    k.axle = c.choice("axle", {"front", "rear"}) == "front" ? Axle::Front : Axle::Rear;
  } else {
    c.string_or("axle", "");
    k.axle = axle_from_name(k.name);
  }
  k.conditions.temperature_C = c.number("temperature_C", Range::closed(-40.0, 140.0));
  k.conditions.temperature_rate_C_per_s = c.number_or("temperature_rate_C_per_s", 0.0, Range::closed(-10.0, 10.0));
  if (auto w = c.optional_map("wear")) {
    k.conditions.wear_initial_rev = w->number_or("initial_rev", 0.0, Range::closed(-1.0, 5.0));
    k.conditions.wear_rate_rev_per_kN_s = w->number_or("rate_rev_per_kN_s", 0.0, Range::closed(0.0, 1.0));
    w->finish();
  }
  if (auto e = c.optional_map("effects")) {
    k.effects = plant::read_effects(*e);
  } else {
    k.effects = plant::EffectsParams{};
  }
  if (auto s = c.optional_map("sensor")) {
    k.sensors = plant::read_sensor_overrides(*s, sc.plant.sensors);
  } else {
    k.sensors = sc.plant.sensors;
  }
  Reader d = c.map("drive");
  k.drive = read_drive(d);
  if (k.drive.mode == DriveMode::Demand) {
    if (!sc.demand) c.fail("drive", "mode 'demand' needs a top-level 'demand:' section");
    if (!k.axle) c.fail("axle", "mode 'demand' needs 'axle: front|rear' when the name is not FL/FR/RL/RR");
  }
  c.finish();
  return k;
}

Scenario read_scenario(Reader& r, const ExtraKeys& extra) {
  Scenario s;
  s.file = r.file();
  s.name = r.string("name");
  if (s.name.empty()) r.fail("name", "must not be empty");
  s.seed = static_cast<std::uint64_t>(r.integer("seed", 0, std::numeric_limits<std::int64_t>::max()));
  s.duration_s = r.number("duration_s", Range{0.0, 1.0e5, true, false});
  s.duration_line = line_of(r.node()["duration_s"]);
  if (r.has("processes")) {
    s.processes_line = line_of(r.node()["processes"]);
    s.processes = r.strings("processes");
  }
  s.plant_dt_s = r.number_or("plant_dt_s", 0.001, Range::closed(1.0e-5, 0.01));
  s.ccu_period_s = r.number_or("ccu_period_s", 0.005, Range::closed(1.0e-4, 1.0));
  if (s.ccu_period_s < s.plant_dt_s) r.fail("ccu_period_s", "must be >= plant_dt_s");
  s.plant_file = config::resolve_relative(r.file(), r.string("plant"));
  s.plant = plant::load_plant_params(s.plant_file);
  if (auto pop = r.optional_map("population")) {
    // One member of a caliper population replaces the plant file's caliper.
    const std::string spec_file = config::resolve_relative(r.file(), pop->string("spec"));
    const PopulationSpec spec = load_population_spec(spec_file);
    const auto member = static_cast<int>(pop->integer("member", 0, spec.count - 1));
    pop->finish();
    s.plant = population_member(spec, member).params;
  }
  if (auto c = r.optional_map("controller")) {
    s.controller = read_controller(*c);
  }
  if (auto d = r.optional_map("demand")) {
    DemandSpec dm;
    dm.max_clamp_force_kN = d->number("max_clamp_force_kN", Range{0.0, 100.0, true, false});
    dm.front_share = d->number("front_share", Range::closed(0.5, 0.9));
    dm.profile = read_breakpoints(*d, "profile", Range::closed(0.0, 1.0));
    finish_with(*d, {"max_clamp_force_kN", "front_share", "profile"});
    s.demand = dm;
  }
  std::vector<Reader> corners = r.maps("corners");
  if (corners.empty()) r.fail("corners", "must list at least one corner");
  std::set<std::string> names;
  for (Reader& c : corners) {
    s.corners.push_back(read_corner(c, s));
    if (!names.insert(s.corners.back().name).second) {
      c.fail("name", "duplicate corner name '" + s.corners.back().name + "'");
    }
  }
  if (extra) extra(r);
  r.finish();
  return s;
}

plant::Interval read_interval(Reader& r, const std::string& key, const plant::Interval& fallback, const Range& range) {
  if (!r.has(key)) {
    r.fail(key, "required key is missing");
  }
  const std::vector<double> v = r.numbers(key, range);
  if (v.size() != 2) r.fail(key, "must be a [min, max] pair");
  if (v[0] > v[1]) r.fail(key, "min must be <= max");
  (void)fallback;
  return plant::Interval{v[0], v[1]};
}

PopulationSpec read_population(Reader& r) {
  PopulationSpec p;
  p.file = r.file();
  p.name = r.string("name");
  if (p.name.empty()) r.fail("name", "must not be empty");
  p.seed = static_cast<std::uint64_t>(r.integer("seed", 0, std::numeric_limits<std::int64_t>::max()));
  p.count = static_cast<int>(r.integer("count", 1, 100000));
  p.temperatures_C = r.numbers("temperatures_C", Range::closed(-40.0, 140.0));
  if (p.temperatures_C.empty()) r.fail("temperatures_C", "must list at least one temperature");
  p.duration_s = r.number("duration_s", Range{0.0, 1.0e5, true, false});
  p.plant_dt_s = r.number("plant_dt_s", Range::closed(1.0e-5, 0.01));
  p.plant_file = config::resolve_relative(r.file(), r.string("plant"));
  p.base = plant::load_plant_params(p.plant_file);
  Reader d = r.map("drive");
  p.drive = read_drive(d);
  if (p.drive.mode != DriveMode::Position) r.fail("drive", "a population drive must be mode 'position' (a rig)");
  Reader g = r.map("ranges");
  plant::PopulationRanges& q = p.ranges;
  q.elements = read_interval(g, "elements", q.elements, Range::closed(1, 1000));
  q.threshold_min_rev = read_interval(g, "threshold_min_rev", q.threshold_min_rev, Range{0.0, 5.0, true, false});
  q.threshold_span_ratio = read_interval(g, "threshold_span_ratio", q.threshold_span_ratio, Range::closed(1.0, 1e6));
  q.threshold_max_limit_rev = g.number("threshold_max_limit_rev", Range{0.0, 5.0, true, false});
  q.log_uniform_share = g.number("log_uniform_share", Range::closed(0.0, 1.0));
  q.half_width_kN = read_interval(g, "half_width_kN", q.half_width_kN, Range{0.0, 100.0, true, false});
  q.force_share_exponent = read_interval(g, "force_share_exponent", q.force_share_exponent, Range::closed(-3.0, 3.0));
  q.share_log_sigma = read_interval(g, "share_log_sigma", q.share_log_sigma, Range::closed(0.0, 3.0));
  q.initial_deflection = read_interval(g, "initial_deflection", q.initial_deflection, Range::closed(-1.0, 1.0));
  q.contact_rev = read_interval(g, "contact_rev", q.contact_rev, Range::closed(-2.0, 10.0));
  q.stiffness_scale = read_interval(g, "stiffness_scale", q.stiffness_scale, Range::closed(0.01, 100.0));
  q.contact_shift_rev_per_C = read_interval(g, "contact_shift_rev_per_C", q.contact_shift_rev_per_C, Range::closed(-1.0, 1.0));
  q.stiffness_change_per_C = read_interval(g, "stiffness_change_per_C", q.stiffness_change_per_C, Range::closed(-0.01, 0.01));
  q.load_cell_noise_kN = read_interval(g, "load_cell_noise_kN", q.load_cell_noise_kN, Range::closed(0.0, 10.0));
  g.finish();
  try {
    q.validate();
  } catch (const std::invalid_argument& e) {
    g.fail("", e.what());
  }
  r.finish();
  return p;
}

}  // namespace

PopulationSpec load_population_spec(const std::string& file) {
  Reader r = Reader::from_file(file);
  return read_population(r);
}

PopulationSpec load_population_spec_string(const std::string& text, const std::string& name) {
  Reader r = Reader::from_string(text, name);
  return read_population(r);
}

Scenario load_scenario(const std::string& file, const ExtraKeys& extra) {
  Reader r = Reader::from_file(file);
  return read_scenario(r, extra);
}

Scenario load_scenario_string(const std::string& text, const std::string& name, const ExtraKeys& extra) {
  Reader r = Reader::from_string(text, name);
  return read_scenario(r, extra);
}

}  // namespace bbw::scenario
