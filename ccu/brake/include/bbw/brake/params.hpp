// Parameters of the CCU's brake functions (config/vehicle/brake_control.yaml, loader
// bbw/brake/brake_yaml.hpp). The CCU's model of the car is its own copy of nominal values: it
// never reads the plant's parameters.
#pragma once

namespace bbw::brake {

struct CarModel {
  double mass_kg = 1093.0;
  double cg_to_front_axle_m = 1.156;
  double cg_to_rear_axle_m = 1.423;
  double cg_height_m = 0.575;
  double track_front_m = 1.387;
  double track_rear_m = 1.364;
  double wheel_radius_m = 0.344;
  double wheel_inertia_kg_m2 = 1.7;
  double pad_mu = 0.38;                 // nominal pad friction
  double front_effective_radius_m = 0.12;
  double rear_effective_radius_m = 0.10;
  double max_clamp_force_kN = 40.0;
  // Understeer gradient of the linear single-track model (rad per m/s^2 of lateral acceleration):
  // the driver's yaw rate is v delta / (L + K_us v^2).
  double understeer_gradient_rad_s2_per_m = 1.6e-4;
  // Driving resistance for the mass estimate: aerodynamic drag (1/2 rho Cd A, N per (m/s)^2) and
  // the rolling-resistance coefficient.
  double drag_N_s2_per_m2 = 0.396;
  double rolling_resistance = 0.013;
};

// The car's mass from its own braking (docs/vehicle.md, "A population of cars"): a laden car
// needs more braking force for the same deceleration than the nominal model's mass asks for.
struct MassEstimateParams {
  bool enabled = true;
  double min_decel_g = 0.2;       // estimated only while the car decelerates at least this
  double time_constant_s = 0.1;   // low-pass of the raw estimate
  double max_factor = 1.5;        // the estimate within [nominal, this x nominal]
  double deadband = 0.1;          // used less this x nominal (its bias on light cars), never below nominal
};

struct PedalDemandParams {
  double full_travel_mm = 80.0;
  double full_force_N = 500.0;
  double force_exponent = 1.6;
  double disagreement = 0.1;            // travel fractions further apart: a sensor fault
  double dead_band = 0.02;              // demand below this is 0
  double full_demand_g = 1.2;           // deceleration asked for at full travel
};

struct SpeedEstimatorParams {
  double up_gain_per_s = 50.0;          // towards the fastest wheel when it reads faster
  // towards it (corrected by the held slip) when it reads slower while braking hard and is not
  // itself under slip control (a wheel under slip control never pulls the estimate down)
  double down_gain_per_s = 0.5;
  double rolling_gain_per_s = 20.0;     // towards it when no wheel is braked hard
  double bias_gain_per_s = 0.5;         // IMU bias learning while rolling freely
  // ... only from wheel accelerations a car can have: a larger one is a sensor's first edge or a
  // dropout (the wheel-speed sensor reads 0 until its first tooth), not the car.
  double bias_max_wheel_accel_m_s2 = 15.0;
  // The wheels' speeds filtered with this time constant for the reference check below.
  double wheel_filter_s = 0.015;
  // A reference wheel: the fastest, its pads off the disc (command at most free_rolling_torque_Nm
  // and, with the caliper model, the model's air gap open) for reference_release_s, and spun up: over reference_window_s its speed less
  // the IMU's integrated speed stayed within reference_tolerance_m_s of its value now. It
  // reads the car's speed (the estimate follows it both ways at rolling_gain_per_s) and teaches
  // the IMU's bias.
  double reference_release_s = 0.06;
  double reference_window_s = 0.05;
  double reference_tolerance_m_s = 0.15;
  // A wheel's pads are off (for the reference below) once its command is at most this torque and,
  // with the caliper model, the model's force is 0 and its air gap open.
  double free_rolling_torque_Nm = 30.0;
};

struct SlipControlParams {
  double target_slip = 0.10;            // initial target
  double min_target_slip = 0.04;
  double max_target_slip = 0.25;
  double activation_margin = 0.02;      // ABS takes over above target - margin ... or a deep wheel decel
  double activation_wheel_decel_m_s2 = 25.0;
  double kp_Nm_per_rad_s = 50.0;        // proportional on wheel-speed error
  double ki_Nm_per_rad = 600.0;         // integral
  double min_speed_m_s = 2.0;           // below it the ABS hands over to the driver's demand
  double mu_filter_s = 0.03;            // tyre mu estimate filter
  // Online target search (extremum seeking with a square-wave dither on the target).
  double dither_slip = 0.015;
  double dither_half_period_s = 0.2;
  double dither_settle_s = 0.08;
  double search_step = 0.01;
  double search_threshold_mu = 0.005;
  // High-to-low mu jump: under control, a wheel decelerating faster than this (m/s^2 at the
  // rim, from the wheel-speed sensor over one period) and beyond target + jump_slip_margin is on
  // a lower mu: the integral drops at once to the torque the tyre carries now (the wheel's torque
  // balance R Fx = T_brake + I dw/dt), times jump_release_factor.
  double jump_wheel_decel_m_s2 = 60.0;
  double jump_slip_margin = 0.05;
  // ... or faster than this whatever its slip (0: off): no tyre on the old surface lets the wheel
  // fall so fast, so the release need not wait the period the slip margin takes.
  double jump_hard_decel_m_s2 = 0.0;
  double jump_release_factor = 0.8;
  // Clamp force kept while the slip controller acts (the pads stay on the disc).
  double active_min_clamp_kN = 0.3;
  // The CCU's model of the e-caliper's answer to its own command (docs/vehicle.md, "The CCU's
  // brake functions"): at or below caliper_release_kN the corner retracts the pads - the force
  // falls (lag caliper_lag_s, at most caliper_rate_kN_s), then the air gap opens over
  // caliper_retract_s; an apply first closes the gap (caliper_gap_s from fully open: nothing
  // brakes), then the force follows the command (the same lag and rate). With the model the PI
  // integral is held while the command is on its way: not up while the gap closes, not down while
  // the model's force is more than release_freeze_margin_Nm above the command.
  bool caliper_model = false;
  double caliper_release_kN = 0.1;
  double caliper_gap_s = 0.14;
  double caliper_retract_s = 0.025;
  double caliper_rate_kN_s = 90.0;
  double caliper_lag_s = 0.02;
  double release_freeze_margin_Nm = 20.0;
};

struct YawLimitParams {
  bool enabled = true;
  double asymmetry_ratio = 0.6;         // a front wheel's ABS torque below this share of the other's: split-mu
  double min_difference_Nm = 300.0;     // ... and more than this apart (noise on low mu is no split)
  double min_mu_difference = 0.0;       // ... and the tyres' estimated mu more than this apart
  double ramp_Nm_per_s = 1000.0;        // how fast the high side may exceed the low side
  double initial_Nm = 200.0;
  // Yaw-rate feedback (from measurements only): the measured yaw rate beyond the one the driver
  // steers for (the steering-angle sensor through the single-track model) takes torque off the
  // high side.
  double yaw_error_gain_Nm_per_rad_s = 8000.0;
  // ... and the heading error (that yaw-rate error integrated since the brake was applied).
  double heading_error_gain_Nm_per_rad = 0.0;
  // Released as the driver counter-steers: the high side may exceed the low side further by this
  // torque per rad of road-wheel steering towards the low side since the split was seen (the
  // moment a counter-steer balances: 2 R l_f C_f / t_f per rad).
  double counter_steer_gain_Nm_per_rad = 0.0;
  // The open-loop part of the high side's allowance (initial_Nm + ramp_Nm_per_s t) saturates here
  // (issue 15 eighth part): without a bound the ramp alone, given time, grants any asymmetry.
  double max_ramp_Nm = 1.0e9;
  // Yaw-moment build-up delay before the split is seen (GMA): once one front wheel goes into slip
  // control while the other is not, the other's torque is held at what its caliper applies then
  // and may rise only at this rate until it also goes into slip control or the split is seen
  // (0: off).
  double pre_split_ramp_Nm_per_s = 0.0;
  // Reference yaw rate latched when the split is seen (true) or the driver's steering now (false).
  bool latch_driver_yaw_rate = false;
  bool rear_select_low = true;
  // The low side's reference is its command but not below this share of the torque its tyre
  // carries at the estimated mu (front and, for select-low, rear).
  double low_side_capacity_share = 0.8;
  // A corner the CCU cannot use (lost, failed): its share of the driver's braking goes to the
  // other axle's wheel on the same side (no yaw moment from the shift) and the front wheel it
  // leaves alone on its axle may exceed it by the yaw moment the same-side rear wheel's extra
  // torque balances plus lost_corner_initial_Nm + lost_corner_ramp_Nm_per_s t (less the
  // yaw-rate feedback): a lost corner is a known, steady asymmetry, not a surface to probe.
  bool redistribute_lost_corner = true;
  double lost_corner_initial_Nm = 400.0;
  double lost_corner_ramp_Nm_per_s = 3000.0;
};

struct BrakeControlParams {
  CarModel car;
  PedalDemandParams pedal;
  SpeedEstimatorParams speed;
  SlipControlParams slip;
  YawLimitParams yaw;
  MassEstimateParams mass;
  bool abs_enabled = true;

  void validate() const;  // throws std::invalid_argument
};

}  // namespace bbw::brake
