#include "bbw/plant/params.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace bbw::plant {
namespace {

[[noreturn]] void bad(const char* field, double value, const char* rule) {
  std::ostringstream os;
  os << field << " = " << value << ": " << rule;
  throw std::invalid_argument(os.str());
}
void positive(const char* field, double v) {
  if (!(std::isfinite(v) && v > 0.0)) bad(field, v, "must be > 0");
}
void non_negative(const char* field, double v) {
  if (!(std::isfinite(v) && v >= 0.0)) bad(field, v, "must be >= 0");
}
void finite(const char* field, double v) {
  if (!std::isfinite(v)) bad(field, v, "must be finite");
}
void in_range(const char* field, double v, double lo, double hi, const char* rule) {
  if (!(std::isfinite(v) && v >= lo && v <= hi)) bad(field, v, rule);
}

}  // namespace

void PlantParams::validate() const {
  positive("motor.torque_constant_Nm_per_A", motor.torque_constant_Nm_per_A);
  positive("motor.resistance_Ohm", motor.resistance_Ohm);
  non_negative("motor.inductance_H", motor.inductance_H);
  positive("motor.rotor_inertia_kg_m2", motor.rotor_inertia_kg_m2);
  positive("motor.current_limit_A", motor.current_limit_A);
  positive("transmission.gear_ratio", transmission.gear_ratio);
  in_range("transmission.efficiency", transmission.efficiency, 0.1, 1.0, "must be in [0.1, 1]");
  positive("transmission.lead_mm_per_rev", transmission.lead_mm_per_rev);
  non_negative("transmission.spindle_inertia_kg_m2", transmission.spindle_inertia_kg_m2);
  non_negative("transmission.coulomb_friction_Nm", transmission.coulomb_friction_Nm);
  positive("transmission.coulomb_smoothing_rev_per_s", transmission.coulomb_smoothing_rev_per_s);
  non_negative("transmission.viscous_friction_Nm_per_rev_per_s",
               transmission.viscous_friction_Nm_per_rev_per_s);
  in_range("transmission.retracted_stop_rev", transmission.retracted_stop_rev, -5.0, 0.0, "must be in [-5, 0]");
  finite("curve.contact_rev", curve.contact_rev);
  positive("curve.exp_coefficient_kN", curve.exp_coefficient_kN);
  positive("curve.exp_length_rev", curve.exp_length_rev);
  non_negative("curve.linear_kN_per_rev", curve.linear_kN_per_rev);
  positive("curve.smoothing_rev", curve.smoothing_rev);
  finite("curve.reference_temperature_C", curve.reference_temperature_C);
  finite("curve.contact_shift_rev_per_C", curve.contact_shift_rev_per_C);
  in_range("curve.stiffness_change_per_C", curve.stiffness_change_per_C, -0.01, 0.01,
           "must be in [-0.01, 0.01] (stiffness stays positive over -40..140 C)");
  positive("key_friction.half_width_kN", key_friction.half_width_kN);
  in_range("key_friction.elements", key_friction.elements, 1, 1000, "must be in [1, 1000]");
  positive("key_friction.threshold_median_rev", key_friction.threshold_median_rev);
  in_range("key_friction.threshold_log_sigma", key_friction.threshold_log_sigma, 0.0, 3.0,
           "must be in [0, 3]");
  in_range("key_friction.force_share_exponent", key_friction.force_share_exponent, -3.0, 3.0,
           "must be in [-3, 3]");
  non_negative("key_friction.threshold_min_rev", key_friction.threshold_min_rev);
  non_negative("key_friction.threshold_max_rev", key_friction.threshold_max_rev);
  if (key_friction.threshold_max_rev > 0.0 && !(key_friction.threshold_max_rev >= key_friction.threshold_min_rev)) {
    in_range("key_friction.threshold_max_rev", key_friction.threshold_max_rev, key_friction.threshold_min_rev, 1e300,
             "must be >= threshold_min_rev");
  }
  if (key_friction.threshold_distribution == ThresholdDistribution::LogUniform) {
    positive("key_friction.threshold_min_rev", key_friction.threshold_min_rev);
    positive("key_friction.threshold_max_rev", key_friction.threshold_max_rev);
  }
  in_range("key_friction.share_log_sigma", key_friction.share_log_sigma, 0.0, 3.0, "must be in [0, 3]");
  in_range("key_friction.initial_deflection", key_friction.initial_deflection, -1.0, 1.0, "must be in [-1, 1]");
  in_range("sensors.resolver_counts_per_motor_rev", sensors.resolver_counts_per_motor_rev, 1,
           1 << 24, "must be in [1, 16777216]");
  non_negative("sensors.resolver_noise_rev", sensors.resolver_noise_rev);
  non_negative("sensors.speed_noise_rev_per_s", sensors.speed_noise_rev_per_s);
  non_negative("sensors.load_cell_noise_kN", sensors.load_cell_noise_kN);
  non_negative("sensors.external_noise_kN", sensors.external_noise_kN);
  non_negative("sensors.temperature_noise_C", sensors.temperature_noise_C);
  non_negative("sensors.current_noise_A", sensors.current_noise_A);
  in_range("substeps", substeps, 1, 1000, "must be in [1, 1000]");
  in_range("rated_clamp_force_kN", rated_clamp_force_kN, 1.0, 1000.0, "must be in [1, 1000] kN");
}

void EffectsParams::validate() const {
  non_negative("viscous_friction.coefficient_kN_per_rev_per_s",
               viscous_friction.coefficient_kN_per_rev_per_s);
  non_negative("load_dependent_friction.gain", load_dependent_friction.gain);
  positive("load_dependent_friction.reference_force_kN", load_dependent_friction.reference_force_kN);
  in_range("sensor_delay.delay_s", sensor_delay.delay_s, 0.0, 1.0, "must be in [0, 1]");
  finite("thermal_drift.offset_kN_per_C", thermal_drift.offset_kN_per_C);
  finite("thermal_drift.reference_temperature_C", thermal_drift.reference_temperature_C);
  non_negative("backlash.width_rev", backlash.width_rev);
  in_range("creep.relaxation_fraction", creep.relaxation_fraction, 0.0, 0.9, "must be in [0, 0.9]");
  positive("creep.time_constant_s", creep.time_constant_s);
}

void Conditions::validate() const {
  in_range("temperature_C", temperature_C, -40.0, 140.0, "must be in [-40, 140]");
  finite("temperature_rate_C_per_s", temperature_rate_C_per_s);
  finite("wear_initial_rev", wear_initial_rev);
  non_negative("wear_rate_rev_per_kN_s", wear_rate_rev_per_kN_s);
}

}  // namespace bbw::plant
