// Per-corner fault detection and isolation in the CCU (docs/faults.md, "Detection"). Pure: no
// DDS, clock, file or thread; time comes with the samples and with tick(now_s). Memory is sized
// at construction; update() and tick() do not allocate.
//
// Fed, per sample, the guard's verdict, the reading and (when the calibrator was fed it) the
// calibrator's estimate; fed link events from outside (DDS deadline / liveliness, or the
// in-memory harness). Each part's first confirmed fault is latched as a Diagnosis; link and
// process losses clear when samples arrive again.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <optional>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/faults/reading.hpp"
#include "bbw/faults/sample_guard.hpp"
#include "bbw/faults/schedule.hpp"

namespace bbw::faults {

struct MonitorParams {
  GuardLimits guard;

  // Analytic redundancy: r = (load cell - friction estimate) - curve(position).
  double residual_threshold_kN = 0.6;               // once the calibrator has an accepted fit
  double uncalibrated_residual_threshold_kN = 3.0;  // before it (initial curve, no friction model)
  double residual_persist_s = 0.02;
  // A change of the residual against its own recent level (a low-pass with this time constant,
  // frozen while a fault is suspected) beyond residual_change_threshold_kN is also a
  // disagreement (once calibrated): it catches a step whose sign the standing calibration error
  // partly cancels, or that the local loop's reaction partly hides.
  double residual_reference_s = 0.5;
  double residual_change_threshold_kN = 0.45;
  // Where the curve is trusted: the calibrator's range (CornerSupervisor copies x_min_rev and
  // x_max_rev of the calibrator config here). Outside it the cubic is an extrapolation.
  double curve_min_rev = 1.0;
  double curve_max_rev = 6.0;

  // Resolver consistency: a position step the measured speed does not explain.
  double jump_threshold_rev = 0.01;
  double jump_confirm_s = 0.01;     // a jump not undone within this is an offset
  double jump_window_s = 0.05;      // a jump this recent explains a residual as the resolver's

  // Stuck channels: exactly repeated readings while the other channel moves.
  int stuck_samples = 20;
  double stuck_min_travel_rev = 0.05;         // position range that must move a load cell
  double stuck_min_force_change_kN = 1.0;     // load-cell range that must move a resolver
  int frozen_attribution_samples = 5;         // repeats that name the frozen channel of a residual

  // Noise: in a window of the residual's sample-to-sample changes, the share larger than
  // noise_step_kN (a single step, e.g. a bias or a resolver jump, is one sample, not noise).
  int noise_window_samples = 32;              // <= kMaxNoiseWindow
  double noise_step_kN = 0.25;                // about 6x the healthy change (0.03 kN RMS load cell)
  double noise_min_fraction = 0.25;

  // Dropout: consecutive samples without a load-cell value.
  int dropout_samples = 5;

  // Actuator torque balance: the torque the axial load and the acceleration need,
  // load * Nm_per_kN + J 2 pi a, against the torque the measured current should make,
  // i * torque_per_A; both low-pass filtered, their ratio is the delivered torque fraction.
  double torque_per_A_Nm = 0.27;              // at the spindle (scenario::actuator_model)
  double Nm_per_kN = 0.0398;
  double inertia_kg_m2 = 3.0e-3;              // reflected to the spindle
  double torque_filter_s = 0.01;
  double torque_check_min_load_kN = 8.0;      // drive friction is small against the load above this
  double torque_check_min_torque_Nm = 0.2;    // expected torque below this: no check
  double torque_fraction_threshold = 0.6;     // at standstill, below this: torque loss (kept in use)
  double torque_check_max_speed_rev_per_s = 0.5;
  double torque_persist_s = 0.04;
  double torque_lost_threshold = 0.25;        // at any speed, below this: the actuator is lost
  double torque_lost_persist_s = 0.015;
  // Tracking backstop: the force against a first-order model of the commanded response. A
  // shortfall below both is ActuatorTracking; an excess above both (a brake that does not
  // release) is ActuatorNotReleasing, with the same threshold and persistence.
  double tracking_time_constant_s = 0.1;
  double tracking_threshold_kN = 3.0;
  double tracking_relative = 0.3;             // of the command
  double tracking_persist_s = 0.2;
  double force_limit_kN = 40.0;               // commands above it are not expected to be reached
  // An excess is a brake that does not release only while it does not move back at least this
  // fast (a brake that releases, if slowly, e.g. back-driven after a torque loss, moves).
  double release_min_speed_rev_per_s = 0.5;

  // Link: no sample for this long is a lost link (the DDS deadline in the process).
  double deadline_s = 0.015;

  void validate() const;  // throws std::invalid_argument naming the field, value and rule
};
inline constexpr int kMaxNoiseWindow = 256;

enum class Finding : std::uint8_t {
  None,
  LoadCellOffset,    // residual, no resolver signature (bias, drift)
  LoadCellStuck,
  LoadCellNoisy,
  LoadCellMissing,   // dropout
  ResolverOffset,
  ResolverStuck,
  ActuatorTorqueLoss,  // part of the torque is missing; the loop still reaches the command
  ActuatorLost,        // (almost) no torque for the current drawn
  ActuatorTracking,    // cannot follow a reachable command
  ActuatorNotReleasing,  // holds a force well above the command (jammed, seized): over-application
  LinkLost,          // deadline missed / no samples
  ProcessLost,       // liveliness lost, or a new process of the corner joined
};
const char* to_string(Finding f);
Part part_of(Finding f);  // Finding::None -> Part::LoadCell (unused)

struct Diagnosis {
  bool present = false;    // confirmed at least once
  bool active = false;     // still in force (sensor/actuator findings latch; link/process clear)
  Finding finding = Finding::None;
  double onset_s = 0.0;    // when the condition started (best estimate)
  double detected_s = 0.0; // when it was confirmed
  double finding_s = 0.0;  // when the current finding was confirmed (later after an upgrade)
};

// Restarted: a new process of the corner (a higher incarnation) has sent its first samples, so
// the one before it is gone: an outage still open is the process's death, not the link's.
enum class LinkEvent : std::uint8_t { DeadlineMissed, LivelinessLost, LivelinessRecovered, Restarted };

class FaultMonitor {
 public:
  FaultMonitor(const MonitorParams& params, Target corner);  // throws std::invalid_argument

  // One sample. `check` is the guard's verdict on it; `estimate` is the calibrator's output for
  // it when the calibrator was fed (nullptr otherwise); `force_estimate_kN` is the clamp force
  // the CCU currently believes (NaN when it has none); arrival_s is when the CCU got it.
  void update(const CornerReading& r, const SampleCheck& check, const calibration::Estimate* estimate,
              double force_estimate_kN, double arrival_s);
  void on_link_event(LinkEvent e, double time_s);
  // Deadline check at the CCU's time now_s.
  void tick(double now_s);

  const Diagnosis& diagnosis(Part p) const { return diag_[static_cast<std::size_t>(p)]; }
  bool ok(Part p) const { return !diag_[static_cast<std::size_t>(p)].active; }
  // Samples arrived again after a link or process loss; cleared by take_rejoin().
  bool rejoined() const { return rejoined_; }
  bool take_rejoin();
  // Whether the last loss was the process (liveliness), so its sequence starts again.
  bool process_was_lost() const { return process_lost_since_rejoin_; }
  // Delivered / expected torque, from the last torque check (1 until one ran).
  double torque_fraction() const { return torque_fraction_; }
  // Narrows the residual check to where the calibrator's fits had data.
  void set_curve_range(double min_rev, double max_rev);
  // The last residual inside the curve's range (NaN outside it or before the first).
  double last_residual_kN() const { return residual_kN_; }
  // The last residual minus its reference level (NaN where the residual is).
  double last_residual_change_kN() const { return residual_change_kN_; }
  // Share of large residual steps in the noise window.
  double last_noise_fraction() const { return noise_kN_; }
  Target corner() const { return corner_; }
  const MonitorParams& params() const { return p_; }

 private:
  void confirm(Finding f, double onset_s, double now_s);
  void clear(Part p);
  void check_residual(const CornerReading& r, const calibration::Estimate& e);
  void check_noise(double residual_kN, double t);
  void check_actuator(const CornerReading& r, const SampleCheck& c, double force_estimate_kN, double dt_s);

  MonitorParams p_;
  Target corner_;
  std::array<Diagnosis, 5> diag_{};

  // previous usable sample
  bool have_prev_ = false;
  CornerReading prev_{};
  bool prev_lc_present_ = false;
  // residual
  bool residual_suspect_ = false;
  double residual_onset_s_ = 0.0;
  double residual_kN_ = std::numeric_limits<double>::quiet_NaN();
  double residual_change_kN_ = std::numeric_limits<double>::quiet_NaN();
  bool have_reference_ = false;
  bool reference_calibrated_ = false;  // the calibrator's state when the reference was set
  double reference_kN_ = 0.0;
  double reference_time_s_ = 0.0;
  bool have_prev_residual_ = false;
  double prev_residual_kN_ = 0.0;
  // resolver jumps
  double last_jump_s_ = -1e300;
  double pending_jump_rev_ = 0.0;
  double pending_jump_s_ = 0.0;
  bool jump_pending_ = false;
  // stuck runs
  int lc_repeat_ = 0;
  double lc_run_onset_s_ = 0.0;
  double run_pos_min_ = 0.0, run_pos_max_ = 0.0;
  int pos_repeat_ = 0;
  double pos_run_onset_s_ = 0.0;
  double run_lc_min_ = 0.0, run_lc_max_ = 0.0;
  // noise window of squared residual differences
  std::array<std::uint8_t, kMaxNoiseWindow> noise_big_{};
  int noise_count_ = 0;
  int noise_head_ = 0;
  int noise_big_count_ = 0;
  double noise_kN_ = 0.0;   // share of big steps in the window
  // dropout
  int missing_run_ = 0;
  double missing_onset_s_ = 0.0;
  // actuator
  bool torque_suspect_ = false;
  double torque_onset_s_ = 0.0;
  bool lost_suspect_ = false;
  double lost_onset_s_ = 0.0;
  bool torque_init_ = false;
  double need_Nm_ = 0.0;
  double make_Nm_ = 0.0;
  double curve_min_rev_ = 0.0;
  double curve_max_rev_ = 0.0;
  double torque_fraction_ = 1.0;
  bool tracking_suspect_ = false;
  double tracking_onset_s_ = 0.0;
  bool excess_suspect_ = false;
  double excess_onset_s_ = 0.0;
  bool model_init_ = false;
  double model_kN_ = 0.0;
  // link
  bool any_arrival_ = false;
  double last_arrival_s_ = 0.0;
  bool rejoined_ = false;
  bool process_lost_since_rejoin_ = false;
};

}  // namespace bbw::faults
