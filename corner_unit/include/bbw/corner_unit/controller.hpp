// The corner's local controller: a cascade of position (or clamp-force) loop -> speed loop ->
// motor current command, with a current limit and anti-windup. Pure: time is an argument.
//
//   position mode: v_ref = v_ff + Kx (x_ref - x)                          (test rig)
//   force mode:    v_ref = (dF_ref/dt + wf e + wi * integral(e)) / k,  e = F_ref - F_fb,
//                  k = max(k(F), k_seen)                                 (vehicle)
//                  k(F) = stiffness_at_zero + stiffness_per_kN * F: the nominal curve's slope;
//                  k_seen: the slope the feedback shows against position over the recent travel
//                  (StiffnessEstimate): key friction that sticks after a reversal makes the load
//                  cell 10-100x stiffer than the curve, and a loop gain wf/k(F) then limit-cycles
//                  (issue 14); below release_force_kN the controller returns to release_position_rev.
//   speed loop:    i = Kv (v_ref - v) + Ki integral(v_ref - v) + i_load(F_load) + i_acc(a_ff)
//   the command is clipped to +/- current_limit_A; integrators stop while clipped in the
//   direction of the error (conditional integration).
#pragma once

namespace bbw::corner_unit {

// Nominal actuator data the controller uses for feedforward (from the caliper's data sheet).
struct ActuatorModel {
  double torque_per_A_Nm = 0.27;      // at the spindle: kt * gear ratio * efficiency
  double Nm_per_kN = 0.0398;          // spindle torque per kN of axial load: lead / 2 pi
  double inertia_kg_m2 = 3.0e-3;      // reflected to the spindle
};

struct ControllerParams {
  ActuatorModel actuator;
  double current_limit_A = 40.0;
  double position_gain_per_s = 40.0;
  double speed_gain_A_per_rev_per_s = 14.0;
  double speed_integral_gain_A_per_rev = 560.0;
  double max_speed_rev_per_s = 25.0;
  double force_bandwidth_rad_per_s = 30.0;
  double force_integral_rad_per_s2 = 150.0;
  // If > 0, the force integral learns only while the speed loop follows its reference within
  // this (a steady error the loop can act on): while the rotor cannot follow (a drive backing off
  // a hold against its load and friction at 0.2-0.8 rev/s for a reference of -7 rev/s) it wound
  // up to 10 kN's worth, and a later fast release ran 1.9 rev past its command and left the brake
  // off for 0.21 s (issue 14, tuning seed 1408 run 94; 2 rev/s fixes it). Off by default (0:
  // integrate whenever not clipped): it also changes how a drive that lost two thirds of its
  // torque holds, which the monitor then named lost in a hold (docs/plant.md).
  double force_integral_max_speed_error_rev_per_s = 0.0;
  double stiffness_at_zero_kN_per_rev = 2.5;
  double stiffness_per_kN_per_rev = 0.3;       // (kN/rev) per kN
  double release_force_kN = 0.1;
  double release_position_rev = 0.0;
  // In force mode, behind release_position_rev - force_home_margin_rev the speed reference is at
  // least position_gain_per_s x the distance back to it: the force loop never drives the actuator
  // onto its retracted stop.
  bool force_home_limit = true;
  double force_home_margin_rev = 0.1;
  // When the force feedback's source changes (ControllerInputs::feedback_switched: a CCU fault
  // reaction moves the loop from the load cell to the curve or back), the force loop restarts its
  // stiffness estimate and its force integral: the step between the two sources is no travel of
  // the caliper, and neither the slope nor the integral of the old source's error fits the new
  // one. Without it the step (6.3 kN at 6.36 rev, after 1.2 mrev of travel) read as a 1200
  // kN/rev caliper; the loop, its gain cut 80-fold, backed off at 0.2-0.8 rev/s and wound its
  // integral, which then drove the release from the hard stop 0.66 rev behind the pads' contact
  // (tune_bias run 94). A step while releasing needs nothing: the release restarts both anyway.
  bool feedback_switch_restart = true;
  // Curve feedback (the CCU's calibrated cubic): below this position, or below the cubic's local
  // minimum if that is higher, the estimate is the end-of-line curve scaled to meet the cubic
  // there (a cubic cannot bend to the pads' contact; the CCU's monitor trusts it from 1 rev up).
  double curve_trusted_min_rev = 1.0;
  bool load_feedforward = true;
  // The force loop's stiffness seen in its own feedback (k_seen above). An increment of the
  // regression closes when the position has moved stride_rev or the feedback stride_kN since the
  // last one; increments are forgotten with the travel (exp(-|dx| / memory_rev): the key friction
  // is rate independent) and all at once at a reversal of the motion (every friction element
  // sticks again); the nominal slope counts as one stride of prior data; k_seen <= max_ratio k(F).
  bool stiffness_estimate = true;
  double stiffness_stride_rev = 0.002;
  double stiffness_stride_kN = 0.3;
  double stiffness_memory_rev = 0.02;
  double stiffness_reversal_rev = 2.0e-4;     // an increment this long or longer sets the direction
  double stiffness_max_ratio = 100.0;
  // The feedback terms divide by the largest seen stiffness, forgotten with the travel
  // (exp(-|dx| / hold_rev)): a loop that dithers across a reversal (or a backlash gap, 0.05 rev,
  // where the slope it sees is 0 until the flank meets sticking friction) keeps the low gain the
  // stiff side needs. The rate feedforward divides by the current estimate.
  double stiffness_hold_rev = 0.1;
  // A resolver whose position and speed both repeat exactly over this many samples is frozen
  // (a live resolver's speed is noisy and never repeats): the motor cannot be commutated and
  // the speed loop has no feedback, so the current is 0 until the resolver lives again (without
  // this a stuck resolver wound the speed loop up and drove the caliper into an oscillation of
  // hundreds of kN, tuning seed 1403 run 34). 0: off.
  int frozen_resolver_samples = 20;
  // Actuator test in holds (issue 14): a drive that seizes while it holds a force shows nothing
  // until the next change of command, since the force stays where it is. After hold_test_min_hold_s
  // of a hold (force mode, command >= hold_test_min_force_kN, |speed| <= hold_test_max_speed_rev_per_s,
  // |force error| <= hold_test_max_error_kN), and then every hold_test_period_s, the loops hold their
  // current I and the command is I - a for hold_test_pulse_s, then I + a for as long, with
  // a = |I| + hold_test_current_A: the current changes sign both ways, so the rotor moves even when
  // a gear rests on its flank in a backlash (the load holds it there against any smaller change)
  // or the spindle's friction holds the load; its inertia takes the pulse (about 0.1-0.5 mrev of
  // travel, a clamp force change of a few N to a few tens of N against sticking key friction) and
  // the CCU's monitor compares the rotor's speed with what the measured current gives a free rotor
  // (faults::MonitorParams::test_pulse_*). 0 A: off.
  double hold_test_current_A = 1.5;
  double hold_test_pulse_s = 0.003;          // at most 7 sample periods (the monitor's history)
  double hold_test_period_s = 0.015;
  double hold_test_min_hold_s = 0.015;
  double hold_test_min_force_kN = 1.0;
  double hold_test_max_speed_rev_per_s = 0.5;
  double hold_test_max_error_kN = 1.5;

  void validate() const;  // throws std::invalid_argument naming the field
};

// Where the force loop gets its feedback from.
enum class ForceFeedback { LoadCell, Compensated, Curve, True };
const char* to_string(ForceFeedback f);

// The candidate force signals of one sample, kN.
struct ForceSources {
  double load_cell_kN = 0.0;           // raw internal load cell
  double friction_estimate_kN = 0.0;   // the caller's estimate of the friction in it
  double curve_estimate_kN = 0.0;      // the caller's curve evaluated at the measured position
  double true_kN = 0.0;                // ground truth (simulation / external sensor)
};
double select_force(ForceFeedback f, const ForceSources& s);

struct PositionReference {
  double position_rev = 0.0;
  double speed_rev_per_s = 0.0;        // feedforward; 0 if unknown
  double accel_rev_per_s2 = 0.0;       // feedforward; 0 if unknown
};

struct ControllerInputs {
  double position_rev = 0.0;           // resolver
  double speed_rev_per_s = 0.0;        // resolver speed
  double force_feedback_kN = 0.0;      // force-loop feedback (select_force)
  double load_force_kN = 0.0;          // axial load for the current feedforward (load cell)
  bool feedback_switched = false;      // force_feedback_kN comes from another source than last step
};

// The regression of feedback force on position behind k_seen (sums weighted by the travel).
struct StiffnessEstimate {
  bool started = false;
  double anchor_position_rev = 0.0;    // where the open increment began
  double anchor_force_kN = 0.0;
  double sum_xx_rev2 = 0.0;            // sum w dx^2
  double sum_xf_kN_rev = 0.0;          // sum w dx dF
  int direction = 0;                   // sign of the last increment of at least stiffness_reversal_rev
  double stiffness_kN_per_rev = 0.0;   // the k the rate feedforward used last (max of model and seen)
  double held_kN_per_rev = 0.0;        // the k the feedback terms used last (the held maximum)
};

struct ControllerState {
  double speed_integral_A = 0.0;
  double force_integral_kN_s = 0.0;
  bool releasing = true;               // force mode below release_force_kN
  StiffnessEstimate stiffness;
  // The resolver's last reading and how often it has repeated exactly (position and speed).
  double last_position_rev = 0.0, last_speed_rev_per_s = 0.0;
  int resolver_repeats = 0;
  bool resolver_frozen = false;        // the current is 0 (see frozen_resolver_samples)
  // The actuator test in holds: how long the hold has lasted, the time since the last pulse, and
  // where the running pulse is (< 0: none).
  double hold_s = 0.0;
  double since_test_s = 0.0;
  double pulse_s = -1.0;
  double pulse_base_A = 0.0;           // the loop's current the pulse rides on
};

struct ControllerOutput {
  double current_command_A = 0.0;
  double speed_reference_rev_per_s = 0.0;
  bool saturated = false;
};

class LocalController {
 public:
  explicit LocalController(const ControllerParams& params);  // throws std::invalid_argument

  void reset();
  ControllerOutput update_position(const PositionReference& ref, const ControllerInputs& in, double dt_s);
  // force_rate_kN_per_s: the command's rate of change if known (feedforward), else 0.
  ControllerOutput update_force(double force_command_kN, const ControllerInputs& in, double dt_s,
                                double force_rate_kN_per_s = 0.0);

  const ControllerState& state() const { return s_; }
  const ControllerParams& params() const { return p_; }

 private:
  ControllerOutput speed_loop(double v_ref, double a_ff, const ControllerInputs& in, double dt_s);
  // Counts the resolver's exact repeats; true (and the loops' integrators reset) while frozen.
  bool resolver_frozen(const ControllerInputs& in);
  // Updates the estimate: s_.stiffness.stiffness_kN_per_rev (feedforward) and held_kN_per_rev
  // (feedback), both >= the model.
  void update_stiffness(double model_kN_per_rev, const ControllerInputs& in);
  // The actuator test in holds (ControllerParams::hold_test_*): adds the pulse to `out`.
  void hold_test(double force_command_kN, double error_kN, const ControllerInputs& in, double dt_s,
                 ControllerOutput& out);
  // Within a pulse: its current in `out` (the loops held), true; else false.
  bool pulse_step(double dt_s, ControllerOutput& out);

  ControllerParams p_;
  ControllerState s_;
};

}  // namespace bbw::corner_unit
