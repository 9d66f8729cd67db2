// Actuator torque balance: the torque the axial load and the acceleration need,
// load * Nm_per_kN + J 2 pi a, against the torque the measured current should make,
// i * torque_per_A; both low-pass filtered, their ratio is the delivered torque fraction. Below
// torque_lost_threshold at any speed: ActuatorLost; below torque_fraction_threshold at
// standstill, or at speed with the drive's friction added to the need (applying, or braking a
// release: MonitorParams::torque_loss_braking_threshold; below the moving check's load with the
// larger plausible load, MonitorParams::torque_check_moving_low_load_kN): ActuatorTorqueLoss.
// Near standstill at any load, a made torque that neither the
// load cell's load nor the end-of-line curve's (with its band), the acceleration and the drive's
// friction explain, and of which less than torque_lost_threshold would be needed
// (MonitorParams::unexplained_*): ActuatorLost. A load-cell fault moves only one of the two
// loads, so it is not taken for the actuator's. Not checked while the resolver is faulty, nor while its speed
// repeats exactly (and is not 0) for stuck.frozen_attribution_samples (a real speed carries noise and never does:
// a frozen resolver's acceleration reads 0 while the motor works against the loop's reaction, and
// the balance named a stuck resolver a lost actuator 3 ms before the stuck rule could; issue 14).
#pragma once

#include <array>
#include <optional>

#include "bbw/faults/detectors/detector.hpp"
#include "bbw/plant/clamp_curve.hpp"

namespace bbw::faults {

class TorqueDetector {
 public:
  explicit TorqueDetector(const MonitorParams& p);
  // `load_kN`: the load cell while it is trusted (`load_cell_load`), else the CCU's force estimate.
  // position_known: c.r's position is the caliper's (the resolver healthy, or named offset and
  // compensated). A resolver named offset still measures the speed the rules need (with
  // MonitorParams::torque_after_resolver_offset); without the position the load's range is the
  // load alone.
  void update(const SampleContext& c, double load_kN, bool load_cell_load, bool position_known, const MonitorParams& p,
              DiagnosisArbiter& a);
  // The longest test pulse half the history holds, in samples (two halves and the samples before).
  static constexpr int kMaxPulseSamples = 7;
  static constexpr int kHistory = 2 * kMaxPulseSamples + 2;
  // The most test answers the weak-answer rule averages (MonitorParams::test_pulse_weak_count).
  static constexpr int kMaxWeakCount = 32;
  void on_rejoin() {
    torque_init_ = torque_suspect_ = lost_suspect_ = unexplained_init_ = unexplained_suspect_ = static_init_ = false;
    speed_repeats_ = 0;
    reset_response();
  }
  double fraction() const { return fraction_; }
  // Filtered made - needed torque at the last checked sample (the unexplained-torque rule's).
  double excess_Nm() const { return excess_Nm_; }
  // The samples of a test pulse recognised at this sample (its two halves, which ended with the
  // sample before; answered or not), else 0: the step rule leaves them out of its still window.
  int test_pulse_samples() const { return pulse_samples_; }

 private:
  bool torque_suspect_ = false;
  double torque_onset_s_ = 0.0;
  bool lost_suspect_ = false;
  double lost_onset_s_ = 0.0;
  bool torque_init_ = false;
  double torque_since_s_ = 0.0;  // when the filters below started (their first sample)
  static constexpr double kSettledTimeConstants = 3.0;
  double need_Nm_ = 0.0;
  double make_Nm_ = 0.0;
  double friction_Nm_ = 0.0;  // filtered drive friction at the measured speed
  double fraction_ = 1.0;
  std::optional<plant::ClampCurve> eol_;  // the end-of-line curve: a load the load cell does not give
  bool unexplained_init_ = false;
  bool unexplained_suspect_ = false;
  double need_hi_Nm_ = 0.0;  // filtered need from the larger / smaller plausible load
  double need_lo_Nm_ = 0.0;
  double unexplained_onset_s_ = 0.0;
  double excess_Nm_ = 0.0;
  int speed_repeats_ = 0;  // samples whose speed equals the previous one exactly
  // The corners' actuator test in holds (MonitorParams::test_pulse_*): the last samples' speed and
  // current, and the pulses not answered in a row.
  void reset_response() {
    response_count_ = 0;
    unanswered_ = 0;
    answers_count_ = 0;
  }
  void update_response(const SampleContext& c, const MonitorParams& p, DiagnosisArbiter& a);
  // The weak-answer rule: the mean of the last test_pulse_weak_count answers against the corner's
  // healthy answer (MonitorParams::test_pulse_weak_fraction).
  void judge_answers(double ratio, double pulse_start_s, double now_s, const MonitorParams& p, DiagnosisArbiter& a);
  // After a torque loss is named (MonitorParams::torque_loss_rescales_drive): the remaining
  // fraction estimated then, once; the lost rules may judge the made torque scaled by it.
  void rescale_after_torque_loss(double remaining, const MonitorParams& p, const DiagnosisArbiter& a);
  double motor_scale_ = 1.0;
  std::array<double, kHistory> response_speed_{};
  std::array<double, kHistory> response_current_{};
  int response_count_ = 0;  // consecutive samples held (up to the array's size)
  double response_dt_s_ = 0.0;  // their spacing
  int response_head_ = 0;
  int unanswered_ = 0;
  int pulse_samples_ = 0;  // a pulse recognised at this sample: its samples, else 0
  double unanswered_since_s_ = 0.0;
  double unanswered_sum_ = 0.0;  // the answers of the pulses not answered in a row
  double last_pulse_s_ = 0.0;  // when the last pulse was judged
  // The last test_pulse_weak_count answers (a ring), and the corner's own healthy answer learnt
  // from the answers that left it (their mean; the drive's nominal answer until enough are in).
  std::array<double, kMaxWeakCount> answers_{};
  std::array<double, kMaxWeakCount> answers_start_s_{};  // when each answer's pulse began
  int answers_head_ = 0;
  int answers_count_ = 0;
  double learnt_sum_ = 0.0;
  int learnt_count_ = 0;
  bool weak_suspect_ = false;
  double weak_onset_s_ = 0.0;
  // The seized-in-a-hold rule: where and when the drive stopped, the least made torque since.
  bool static_init_ = false;
  double static_position_rev_ = 0.0;
  double static_since_s_ = 0.0;
  double static_min_make_Nm_ = 0.0;
};

}  // namespace bbw::faults
