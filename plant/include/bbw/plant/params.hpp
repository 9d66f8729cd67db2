// Parameters of the e-caliper plant: plain structs, validated by validate() which names the
// field, its value and the rule it breaks (std::invalid_argument). Defaults are the values in
// config/plant/ecaliper.yaml and describe one plausible e-caliper; docs/plant.md explains each.
#pragma once

#include <cmath>
#include <cstdint>

namespace bbw::plant {

// DC motor, current-commanded through its power stage.
struct MotorParams {
  double torque_constant_Nm_per_A = 0.025;
  double resistance_Ohm = 0.3;
  double inductance_H = 2.0e-4;        // 0: the current follows the command at once
  double rotor_inertia_kg_m2 = 2.0e-5;
  double current_limit_A = 40.0;       // the power stage clips the command to +/- this
};

// Planetary gear + ball screw + load sleeve. Position x is in actuator (spindle) revolutions.
struct TransmissionParams {
  double gear_ratio = 12.0;                     // motor revolutions per actuator revolution
  double efficiency = 0.9;                      // gear + ball screw, applied to the motor torque
  double lead_mm_per_rev = 0.25;                // pad travel per actuator revolution
  double spindle_inertia_kg_m2 = 1.0e-4;        // actuator side (spindle, nut, sleeve)
  double coulomb_friction_Nm = 0.05;            // drive friction at the spindle (smoothed sign)
  double coulomb_smoothing_rev_per_s = 0.2;     // speed at which tanh() reaches 76 % of it
  double viscous_friction_Nm_per_rev_per_s = 0.002;
  // The retracted end stop (actuator rev; the released home is 0): the motor cannot turn the
  // spindle back past it, and a rotor that reaches it stops there. Without it a drive that lost
  // its torque while the load spun it back, or a loop that released after a drifting load cell,
  // coasted or ran on tens to hundreds of revolutions (tuning seed 1401 runs 81 and 301).
  double retracted_stop_rev = -0.8;
};

// The drive's friction torque at the spindle at `speed_rev_per_s`: smoothed Coulomb plus viscous
// (the plant's, and the fault monitor's model of it).
inline double drive_friction_Nm(const TransmissionParams& t, double speed_rev_per_s) {
  return t.coulomb_friction_Nm * std::tanh(speed_rev_per_s / t.coulomb_smoothing_rev_per_s) +
         t.viscous_friction_Nm_per_rev_per_s * speed_rev_per_s;
}

// True clamp force versus actuator position (the characteristic curve):
//   delta   = x - x_contact(T, wear)
//   delta_s = smoothing * ln(1 + exp(delta / smoothing))      (a smooth max(delta, 0))
//   F       = s(T) * (exp_coefficient * (exp(delta_s / exp_length) - 1) + linear * delta_s)
//   x_contact(T, wear) = contact + contact_shift_per_C * (T - T_ref) + wear
//   s(T)    = 1 + stiffness_change_per_C * (T - T_ref)
struct ClampCurveParams {
  double contact_rev = 0.5;
  double exp_coefficient_kN = 3.0;
  double exp_length_rev = 2.4;
  double linear_kN_per_rev = 1.8;
  double smoothing_rev = 0.08;
  double reference_temperature_C = 40.0;
  double contact_shift_rev_per_C = 0.004;     // hotter: the caliper opens, contact comes later
  double stiffness_change_per_C = -0.004;     // hotter: softer pads
};

// Key/keyway pre-sliding friction seen by the internal load cell: a generalised Maxwell-slip
// model of `elements` elasto-slip elements whose thresholds are drawn (seeded by
// structure_seed) from a log-normal distribution with the given median and log-sigma, and whose
// force shares K_i Delta_i follow the smooth density Delta_i^force_share_exponent, normalised so
// that sum K_i Delta_i = half_width_kN.
//
// The caliper population (bbw/plant/population.hpp) also draws log-uniform thresholds in
// [threshold_min_rev, threshold_max_rev], clips log-normal draws to that range when
// threshold_max_rev > 0, makes the force shares uneven (each share times exp(share_log_sigma
// N(0, 1)), from the structure seed), and starts the friction deflected: at reset every element
// sits at normalised deflection initial_deflection in [-1, 1] (1 = all slipping upwards). The
// defaults reproduce the plant file's model (log-normal, unclipped, smooth shares, relaxed).
enum class ThresholdDistribution { LogNormal, LogUniform };

struct KeyFrictionParams {
  double half_width_kN = 1.0;
  int elements = 40;
  double threshold_median_rev = 0.08;
  double threshold_log_sigma = 0.6;
  double force_share_exponent = 0.5;
  std::uint64_t structure_seed = 20240521;
  ThresholdDistribution threshold_distribution = ThresholdDistribution::LogNormal;
  double threshold_min_rev = 0.0;
  double threshold_max_rev = 0.0;     // 0: log-normal draws unclipped
  double share_log_sigma = 0.0;
  double initial_deflection = 0.0;
};

// Sensor models. Noise is Gaussian with the given RMS, drawn from the corner's seeded generator.
struct SensorParams {
  int resolver_counts_per_motor_rev = 4096;     // quantisation of the motor angle
  double resolver_noise_rev = 2.0e-5;           // actuator revolutions RMS
  double speed_noise_rev_per_s = 0.005;
  double load_cell_noise_kN = 0.03;
  double external_noise_kN = 0.005;             // external (test rig) force sensor
  double temperature_noise_C = 0.05;
  double current_noise_A = 0.02;
};

struct PlantParams {
  MotorParams motor;
  TransmissionParams transmission;
  ClampCurveParams curve;
  KeyFrictionParams key_friction;
  SensorParams sensors;
  int substeps = 10;                            // integration substeps per step() call
  // The caliper's rated clamp-force range [0, rated]: the corner refuses to command more
  // (issue 17, corner_unit/include/bbw/corner/command_gate.hpp).
  double rated_clamp_force_kN = 40.0;

  void validate() const;  // throws std::invalid_argument
};

// Effects the calibrator does not model; each is off by default and set per corner.
struct ViscousFrictionEffect {
  bool enabled = false;
  double coefficient_kN_per_rev_per_s = 0.2;    // load-cell term c * dx/dt
};
struct LoadDependentFrictionEffect {
  bool enabled = false;
  double gain = 1.0;                            // key friction * (1 + gain * F_true / F_ref)
  double reference_force_kN = 40.0;
};
struct SensorDelayEffect {
  bool enabled = false;
  double delay_s = 0.005;                       // force channel lags the position channel
};
struct ThermalDriftEffect {
  bool enabled = false;
  double offset_kN_per_C = 0.02;                // load-cell offset per degree above the reference
  double reference_temperature_C = 40.0;
};
struct BacklashEffect {
  bool enabled = false;
  double width_rev = 0.05;                      // total play between motor side and spindle
};
struct CreepEffect {
  bool enabled = false;
  double relaxation_fraction = 0.05;            // share of a fast load step that relaxes away
  double time_constant_s = 1.0;
};

struct EffectsParams {
  ViscousFrictionEffect viscous_friction;
  LoadDependentFrictionEffect load_dependent_friction;
  SensorDelayEffect sensor_delay;
  ThermalDriftEffect thermal_drift;
  BacklashEffect backlash;
  CreepEffect creep;

  void validate() const;  // throws std::invalid_argument
};

// The corner's surroundings: temperature (optionally ramped) and pad wear.
struct Conditions {
  double temperature_C = 40.0;
  double temperature_rate_C_per_s = 0.0;
  double wear_initial_rev = 0.0;            // contact point shift already present
  double wear_rate_rev_per_kN_s = 0.0;      // contact shift per kN*s of clamp force

  void validate() const;  // throws std::invalid_argument
};

}  // namespace bbw::plant
