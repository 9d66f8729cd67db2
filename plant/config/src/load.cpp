#include "bbw/plant/params_yaml.hpp"

#include <limits>
#include <stdexcept>

namespace bbw::plant {

using config::Range;
using config::Reader;

namespace {

SensorParams read_sensors(Reader& r, const SensorParams& base, bool required) {
  SensorParams s = base;
  auto num = [&](const char* key, double fallback, const Range& range) {
    return required ? r.number(key, range) : r.number_or(key, fallback, range);
  };
  s.resolver_counts_per_motor_rev = static_cast<int>(
      required ? r.integer("resolver_counts_per_motor_rev", 1, 1 << 24)
               : r.integer_or("resolver_counts_per_motor_rev", base.resolver_counts_per_motor_rev, 1, 1 << 24));
  s.resolver_noise_rev = num("resolver_noise_rev", base.resolver_noise_rev, Range::closed(0, 0.1));
  s.speed_noise_rev_per_s = num("speed_noise_rev_per_s", base.speed_noise_rev_per_s, Range::closed(0, 10));
  s.load_cell_noise_kN = num("load_cell_noise_kN", base.load_cell_noise_kN, Range::closed(0, 5));
  s.external_noise_kN = num("external_noise_kN", base.external_noise_kN, Range::closed(0, 5));
  s.temperature_noise_C = num("temperature_noise_C", base.temperature_noise_C, Range::closed(0, 10));
  s.current_noise_A = num("current_noise_A", base.current_noise_A, Range::closed(0, 10));
  r.finish();
  return s;
}

// Converts a std::invalid_argument from validate() into a ConfigError at the mapping.
template <typename F>
void checked(const Reader& r, F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    r.fail("", e.what());
  }
}

}  // namespace

PlantParams read_plant_params(Reader& r) {
  PlantParams p;
  {
    Reader m = r.map("motor");
    p.motor.torque_constant_Nm_per_A = m.number("torque_constant_Nm_per_A", Range::positive());
    p.motor.resistance_Ohm = m.number("resistance_Ohm", Range::positive());
    p.motor.inductance_H = m.number_or("inductance_H", 0.0, Range::closed(0.0, 1.0));
    p.motor.rotor_inertia_kg_m2 = m.number("rotor_inertia_kg_m2", Range::positive());
    p.motor.current_limit_A = m.number("current_limit_A", Range::positive());
    m.finish();
  }
  {
    Reader t = r.map("transmission");
    p.transmission.gear_ratio = t.number("gear_ratio", Range::positive());
    p.transmission.efficiency = t.number("efficiency", Range::closed(0.1, 1.0));
    p.transmission.lead_mm_per_rev = t.number("lead_mm_per_rev", Range::positive());
    p.transmission.spindle_inertia_kg_m2 = t.number("spindle_inertia_kg_m2", Range::non_negative());
    p.transmission.coulomb_friction_Nm = t.number("coulomb_friction_Nm", Range::non_negative());
    p.transmission.coulomb_smoothing_rev_per_s = t.number("coulomb_smoothing_rev_per_s", Range::positive());
    p.transmission.viscous_friction_Nm_per_rev_per_s =
        t.number("viscous_friction_Nm_per_rev_per_s", Range::non_negative());
    p.transmission.retracted_stop_rev = t.number("retracted_stop_rev", Range::closed(-5.0, 0.0));
    t.finish();
  }
  {
    Reader c = r.map("clamp_curve");
    p.curve.contact_rev = c.number("contact_rev", Range::closed(-5.0, 10.0));
    p.curve.exp_coefficient_kN = c.number("exp_coefficient_kN", Range::positive());
    p.curve.exp_length_rev = c.number("exp_length_rev", Range::positive());
    p.curve.linear_kN_per_rev = c.number("linear_kN_per_rev", Range::non_negative());
    p.curve.smoothing_rev = c.number("smoothing_rev", Range::positive());
    p.curve.reference_temperature_C = c.number("reference_temperature_C", Range::closed(-40.0, 140.0));
    p.curve.contact_shift_rev_per_C = c.number("contact_shift_rev_per_C", Range::closed(-0.1, 0.1));
    p.curve.stiffness_change_per_C = c.number("stiffness_change_per_C", Range::closed(-0.01, 0.01));
    c.finish();
  }
  {
    Reader k = r.map("key_friction");
    p.key_friction.half_width_kN = k.number("half_width_kN", Range::positive());
    p.key_friction.elements = static_cast<int>(k.integer("elements", 1, 1000));
    p.key_friction.threshold_median_rev = k.number("threshold_median_rev", Range::positive());
    p.key_friction.threshold_log_sigma = k.number("threshold_log_sigma", Range::closed(0.0, 3.0));
    p.key_friction.force_share_exponent = k.number("force_share_exponent", Range::closed(-3.0, 3.0));
    p.key_friction.structure_seed = static_cast<std::uint64_t>(
        k.integer("structure_seed", 0, std::numeric_limits<std::int64_t>::max()));
    k.finish();
  }
  {
    Reader s = r.map("sensors");
    p.sensors = read_sensors(s, p.sensors, true);
  }
  p.substeps = static_cast<int>(r.integer_or("substeps", p.substeps, 1, 1000));
  p.rated_clamp_force_kN = r.number_or("rated_clamp_force_kN", p.rated_clamp_force_kN, Range::closed(1.0, 1000.0));
  r.finish();
  checked(r, [&] { p.validate(); });
  return p;
}

PlantParams load_plant_params(const std::string& file) {
  Reader r = Reader::from_file(file);
  return read_plant_params(r);
}

EffectsParams read_effects(Reader& r) {
  EffectsParams e;
  if (auto m = r.optional_map("viscous_friction")) {
    e.viscous_friction.enabled = m->boolean_or("enabled", true);
    e.viscous_friction.coefficient_kN_per_rev_per_s = m->number_or(
        "coefficient_kN_per_rev_per_s", e.viscous_friction.coefficient_kN_per_rev_per_s, Range::closed(0, 100));
    m->finish();
  }
  if (auto m = r.optional_map("load_dependent_friction")) {
    auto& x = e.load_dependent_friction;
    x.enabled = m->boolean_or("enabled", true);
    x.gain = m->number_or("gain", x.gain, Range::closed(0, 100));
    x.reference_force_kN = m->number_or("reference_force_kN", x.reference_force_kN, Range::positive());
    m->finish();
  }
  if (auto m = r.optional_map("sensor_delay")) {
    auto& x = e.sensor_delay;
    x.enabled = m->boolean_or("enabled", true);
    x.delay_s = m->number_or("delay_s", x.delay_s, Range::closed(0, 1));
    m->finish();
  }
  if (auto m = r.optional_map("thermal_drift")) {
    auto& x = e.thermal_drift;
    x.enabled = m->boolean_or("enabled", true);
    x.offset_kN_per_C = m->number_or("offset_kN_per_C", x.offset_kN_per_C, Range::closed(-1, 1));
    x.reference_temperature_C =
        m->number_or("reference_temperature_C", x.reference_temperature_C, Range::closed(-40, 140));
    m->finish();
  }
  if (auto m = r.optional_map("backlash")) {
    auto& x = e.backlash;
    x.enabled = m->boolean_or("enabled", true);
    x.width_rev = m->number_or("width_rev", x.width_rev, Range::closed(0, 1));
    m->finish();
  }
  if (auto m = r.optional_map("creep")) {
    auto& x = e.creep;
    x.enabled = m->boolean_or("enabled", true);
    x.relaxation_fraction = m->number_or("relaxation_fraction", x.relaxation_fraction, Range::closed(0, 0.9));
    x.time_constant_s = m->number_or("time_constant_s", x.time_constant_s, Range::closed(1e-3, 1e4));
    m->finish();
  }
  r.finish();
  checked(r, [&] { e.validate(); });
  return e;
}

SensorParams read_sensor_overrides(Reader& r, const SensorParams& base) {
  return read_sensors(r, base, false);
}

}  // namespace bbw::plant
