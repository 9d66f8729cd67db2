#include "bbw/plant/plant.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "bbw/model/play.hpp"

namespace bbw::plant {
namespace {

constexpr double kTwoPi = 6.283185307179586;

std::size_t delay_capacity(const EffectsParams& e, double min_step_s) {
  if (!(min_step_s > 0.0)) throw std::invalid_argument("Plant: min_step_s must be > 0");
  if (!e.sensor_delay.enabled) return 2;
  return static_cast<std::size_t>(std::ceil(e.sensor_delay.delay_s / min_step_s)) + 3;
}

}  // namespace

Plant::Plant(const PlantParams& params, const EffectsParams& effects, const Conditions& conditions,
             std::uint64_t noise_seed, double min_step_s)
    : p_(params),
      e_(effects),
      c_(conditions),
      curve_(params.curve),
      friction_(params.key_friction),
      force_delay_(delay_capacity(effects, min_step_s)),
      rng_(noise_seed) {
  p_.validate();
  e_.validate();
  c_.validate();
  const auto& m = p_.motor;
  const auto& t = p_.transmission;
  inertia_kg_m2_ = m.rotor_inertia_kg_m2 * t.gear_ratio * t.gear_ratio + t.spindle_inertia_kg_m2;
  torque_per_A_Nm_ = m.torque_constant_Nm_per_A * t.gear_ratio * t.efficiency;
  Nm_per_kN_ = 1000.0 * t.lead_mm_per_rev * 1.0e-3 / kTwoPi;
  quantum_rev_ = 1.0 / (static_cast<double>(p_.sensors.resolver_counts_per_motor_rev) * t.gear_ratio);
  const double f = e_.creep.enabled ? e_.creep.relaxation_fraction : 0.0;
  creep_gain_ = f / (1.0 - f);
  reset(0.0);
}

double Plant::holding_current_A(double force_kN) const {
  return force_kN * Nm_per_kN_ / torque_per_A_Nm_;
}

void Plant::reset(double position_rev) {
  s_ = PlantState{};
  s_.motor_position_rev = position_rev;
  s_.position_rev = position_rev;
  s_.temperature_C = c_.temperature_C;
  s_.wear_rev = c_.wear_initial_rev;
  s_.curve_force_kN = curve_.force_kN(position_rev, s_.temperature_C, s_.wear_rev);
  s_.force_true_kN = s_.curve_force_kN;
  friction_.reset(position_rev);
  s_.key_friction_kN = friction_.force_kN();
  s_.friction_kN = s_.key_friction_kN;
  force_delay_.clear();
  meas_ = Measurement{};
  sample_sensors();
}

void Plant::substep(double i_cmd_A, double torque_scale, bool seized, double h_s) {
  const auto& m = p_.motor;
  const auto& t = p_.transmission;
  // Current: first-order R/L lag towards the (clipped) command.
  if (m.inductance_H > 0.0) {
    s_.current_A += (i_cmd_A - s_.current_A) * -std::expm1(-h_s * m.resistance_Ohm / m.inductance_H);
  } else {
    s_.current_A = i_cmd_A;
  }
  // Axial load on the spindle: clamp force plus the friction at the key. With backlash the
  // motor carries it only while the gear rests on its load-carrying flank.
  const double half_play = e_.backlash.enabled ? 0.5 * e_.backlash.width_rev : 0.0;
  const double gap = s_.motor_position_rev - s_.position_rev;
  const bool loaded = !e_.backlash.enabled || gap >= half_play - 1e-12;
  const double load_Nm = loaded ? (s_.force_true_kN + s_.friction_kN) * Nm_per_kN_ : 0.0;
  const double v = s_.speed_rev_per_s;
  const double accel_rev_s2 =
      (torque_scale * torque_per_A_Nm_ * s_.current_A - load_Nm - drive_friction_Nm(t, v)) / (inertia_kg_m2_ * kTwoPi);
  // Semi-implicit Euler: speed first, then position with the new speed.
  s_.speed_rev_per_s = seized ? 0.0 : s_.speed_rev_per_s + h_s * accel_rev_s2;
  s_.motor_position_rev += h_s * s_.speed_rev_per_s;
  // The retracted end stop: inelastic.
  if (s_.motor_position_rev < t.retracted_stop_rev) {
    s_.motor_position_rev = t.retracted_stop_rev;
    s_.speed_rev_per_s = std::max(0.0, s_.speed_rev_per_s);
  }
  const double x_prev = s_.position_rev;
  if (e_.backlash.enabled) {
    // Play operator: the spindle stays put (held by its own friction) inside the gap.
    calibration::play_step(s_.position_rev, s_.motor_position_rev, e_.backlash.width_rev);
  } else {
    s_.position_rev = s_.motor_position_rev;
  }
  s_.spindle_speed_rev_per_s = (s_.position_rev - x_prev) / h_s;
  // Pads: relaxed curve plus the standard-linear-solid excess that decays with tau.
  const double fc = curve_.force_kN(s_.position_rev, s_.temperature_C, s_.wear_rev);
  if (e_.creep.enabled) {
    s_.creep_kN += creep_gain_ * (fc - s_.curve_force_kN);
    s_.creep_kN *= std::exp(-h_s / e_.creep.time_constant_s);
  }
  s_.curve_force_kN = fc;
  // The pads push, never pull: a fast release that leaves the creep's excess below the relaxed
  // curve (negative) takes the pads off the disc at no clamp force, not at a negative one (a
  // release from a 17 kN hold to 0 read -0.73 kN of true clamp force before the twenty-fourth
  // session).
  s_.force_true_kN = std::max(0.0, fc + s_.creep_kN);
  s_.wear_rev += c_.wear_rate_rev_per_kN_s * std::max(s_.force_true_kN, 0.0) * h_s;
}

const Measurement& Plant::step(const PlantInputs& inputs, double dt_s) {
  if (!(dt_s > 0.0)) return meas_;  // time does not run backwards; nothing happens
  const double limit = p_.motor.current_limit_A;
  const double i_cmd = std::clamp(inputs.current_command_A, -limit, limit);
  const double torque_scale = std::clamp(inputs.torque_scale, 0.0, 1.0);
  const int n = p_.substeps;
  const double h = dt_s / n;
  for (int k = 0; k < n; ++k) {
    s_.time_s += h;
    s_.temperature_C = std::isnan(inputs.temperature_C) ? c_.temperature_C + c_.temperature_rate_C_per_s * s_.time_s
                                                        : inputs.temperature_C;
    substep(i_cmd, torque_scale, inputs.seized, h);
  }
  // Key friction: rate-independent, so one update per step at the step's end position is
  // exact for a position that moves monotonically within the step.
  double key = friction_.step(s_.position_rev);
  if (e_.load_dependent_friction.enabled) {
    key *= 1.0 + e_.load_dependent_friction.gain * std::max(s_.force_true_kN, 0.0) /
                     e_.load_dependent_friction.reference_force_kN;
  }
  s_.key_friction_kN = key;
  s_.friction_kN = key;
  if (e_.viscous_friction.enabled) {
    s_.friction_kN += e_.viscous_friction.coefficient_kN_per_rev_per_s * s_.spindle_speed_rev_per_s;
  }
  s_.load_cell_offset_kN =
      e_.thermal_drift.enabled
          ? e_.thermal_drift.offset_kN_per_C * (s_.temperature_C - e_.thermal_drift.reference_temperature_C)
          : 0.0;
  sample_sensors();
  return meas_;
}

void Plant::sample_sensors() {
  const auto& sn = p_.sensors;
  meas_.time_s = s_.time_s;
  const double x_noisy = s_.motor_position_rev + sn.resolver_noise_rev * normal_(rng_);
  meas_.position_rev = std::round(x_noisy / quantum_rev_) * quantum_rev_;
  meas_.speed_rev_per_s = s_.speed_rev_per_s + sn.speed_noise_rev_per_s * normal_(rng_);
  double load_cell = s_.force_true_kN + s_.friction_kN + s_.load_cell_offset_kN;
  if (e_.sensor_delay.enabled) {
    force_delay_.push(s_.time_s, load_cell);
    load_cell = force_delay_.read(s_.time_s - e_.sensor_delay.delay_s);
  }
  meas_.force_internal_kN = load_cell + sn.load_cell_noise_kN * normal_(rng_);
  meas_.force_external_kN = s_.force_true_kN + sn.external_noise_kN * normal_(rng_);
  meas_.temperature_C = s_.temperature_C + sn.temperature_noise_C * normal_(rng_);
  meas_.motor_current_A = s_.current_A + sn.current_noise_A * normal_(rng_);
}

}  // namespace bbw::plant
