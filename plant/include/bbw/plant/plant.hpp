// The e-caliper plant: current-commanded DC motor, planetary gear, ball screw, load sleeve,
// pads; key/keyway friction on the load cell; resolver, load cell, external force sensor,
// temperature and current sensors; and the unmodelled effects of EffectsParams.
//
// Pure: no files, clock or threads. Time advances only through step(inputs, dt_s), which
// integrates with PlantParams::substeps internal substeps and never allocates.
#pragma once

#include <limits>

#include <cstdint>
#include <random>

#include "bbw/plant/clamp_curve.hpp"
#include "bbw/model/delay_line.hpp"
#include "bbw/plant/key_friction.hpp"
#include "bbw/plant/params.hpp"

namespace bbw::plant {

struct PlantInputs {
  double current_command_A = 0.0;  // to the power stage; clipped to +/- current_limit_A
  // Fault injection (docs/faults.md): the fraction of the motor's torque that reaches the
  // spindle, in [0, 1]; 1 is a healthy actuator. The current (and its sensor) is unaffected.
  double torque_scale = 1.0;
  // Fault injection: the mechanism is jammed (gear or screw seized). Motor and spindle cannot
  // turn whatever the torque; the clamp force stays where the pads hold it (creep still
  // relaxes it). The current follows its command as before.
  bool seized = false;
  // The caliper's temperature from outside (a vehicle run: the brake disc heats it; issue 15).
  // NaN (the default): the corner's Conditions (temperature and its ramp) as before.
  double temperature_C = std::numeric_limits<double>::quiet_NaN();
};

// Physical state (the truth).
struct PlantState {
  double time_s = 0.0;
  double motor_position_rev = 0.0;  // motor side, in actuator revolutions (resolver side)
  double speed_rev_per_s = 0.0;     // motor side, actuator revolutions per second
  double position_rev = 0.0;        // spindle (actuator) position; differs by backlash
  double spindle_speed_rev_per_s = 0.0;
  double current_A = 0.0;
  double temperature_C = 0.0;
  double wear_rev = 0.0;            // contact point shift from pad wear
  double curve_force_kN = 0.0;      // relaxed characteristic-curve force at position_rev
  double creep_kN = 0.0;            // viscoelastic (standard-linear-solid) excess force
  double force_true_kN = 0.0;       // clamp force on the disc = curve_force + creep
  double key_friction_kN = 0.0;     // Maxwell-slip key friction (load-dependent scaling applied)
  double friction_kN = 0.0;         // all friction the load cell sees: key + viscous term
  double load_cell_offset_kN = 0.0; // thermal drift offset
};

// What the sensors report for one step.
struct Measurement {
  double time_s = 0.0;
  double position_rev = 0.0;        // resolver (motor side), quantised + noise
  double speed_rev_per_s = 0.0;     // resolver speed + noise
  double force_internal_kN = 0.0;   // load cell: true + friction + offset + noise (delayed)
  double force_external_kN = 0.0;   // external sensor (test rig): true + noise
  double temperature_C = 0.0;
  double motor_current_A = 0.0;
};

class Plant {
 public:
  // min_step_s: the shortest dt_s step() will be called with; sizes the sensor-delay buffer.
  // Throws std::invalid_argument on invalid parameters.
  Plant(const PlantParams& params, const EffectsParams& effects, const Conditions& conditions,
        std::uint64_t noise_seed, double min_step_s = 1.0e-3);

  // Relaxed, at rest, at position x (both motor side and spindle), time 0, no current.
  void reset(double position_rev);

  // Advances by dt_s (> 0) and samples the sensors. Allocation-free.
  const Measurement& step(const PlantInputs& inputs, double dt_s);

  const Measurement& measurement() const { return meas_; }
  const PlantState& state() const { return s_; }
  const PlantParams& params() const { return p_; }
  const EffectsParams& effects() const { return e_; }
  const Conditions& conditions() const { return c_; }
  const ClampCurve& curve() const { return curve_; }
  const KeyFriction& key_friction() const { return friction_; }

  // Current the motor needs to hold force F at standstill (Nm balance, no friction), A.
  double holding_current_A(double force_kN) const;
  // Resolver quantum in actuator revolutions.
  double resolver_quantum_rev() const { return quantum_rev_; }

 private:
  void substep(double i_cmd_A, double torque_scale, bool seized, double h_s);
  void sample_sensors();

  PlantParams p_;
  EffectsParams e_;
  Conditions c_;
  ClampCurve curve_;
  KeyFriction friction_;
  common::DelayLine force_delay_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  double inertia_kg_m2_ = 0.0;        // reflected to the spindle
  double torque_per_A_Nm_ = 0.0;      // at the spindle, efficiency included
  double Nm_per_kN_ = 0.0;            // spindle torque per kN of axial load
  double quantum_rev_ = 0.0;
  double creep_gain_ = 0.0;           // f / (1 - f)
  PlantState s_;
  Measurement meas_;
};

}  // namespace bbw::plant
