// CcuNode: the central control unit's logic, pure (no DDS, file, thread or clock). It grows
// CcuCore (one CornerSupervisor per corner: sample guard, calibrator, fault monitor, reactions;
// the Redistributor) by the per-corner bookkeeping a CCU needs around it: block and sample
// numbering and gaps, incarnations (restarted corners), the flood guard, link events, the
// lockstep barrier, the commands and calibration states to send, and the detection log.
//
// Typed messages in (MeasurementBlock, CornerHealth) with the sending endpoint; typed messages
// out (ClampCommand, CalibrationState); time is an argument. The CCU process (ccu/process) is its
// DDS adapter, the in-process runner (bbw/node/in_process.hpp) its in-memory one. Logging is an
// observer (CcuObserver).
#pragma once

#include <bbw/idl/bbw_msgs.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "bbw/common/corner.hpp"
#include "bbw/faults/schedule.hpp"
#include "bbw/node/ccu_core.hpp"
#include "bbw/node/lockstep_barrier.hpp"
#include "bbw/transport/ports.hpp"

namespace bbw::node {

using ccu::CcuCore;
using ccu::CornerPlan;
using ccu::SampleOutcome;

// One detection (a diagnosis confirmed, or confirmed again after it had cleared).
struct DetectionRecord {
  std::size_t slot = 0;
  faults::Finding finding = faults::Finding::None;
  double onset_s = 0.0;
  double detected_s = 0.0;
};

struct CornerChannel {
  Corner corner = Corner::FL;
  std::size_t slot = 0;       // corner_index(corner)
  std::size_t barrier = 0;    // the corner's index in the lockstep barrier
  std::uint64_t next_sample_seq = 1;
  std::uint32_t incarnation = 0;
  std::uint64_t blocks_received = 0;
  std::uint64_t samples_received = 0;
  std::uint64_t samples_invalid = 0;   // rejected by the sample guard
  // Received in this corner's partition with another corner id (a corner posing as another,
  // or a corner id that does not exist): dropped before anything reads them.
  std::uint64_t foreign_blocks = 0;
  std::uint64_t foreign_health = 0;
  // Flood guard: a token bucket of blocks this corner may still have processed (refilled by
  // kBlocksPerPeriod every CCU period up to kBlockBurst); blocks beyond it are taken and dropped
  // unread, so a corner sending at many times its rate cannot take the CCU's time from the
  // others (docs/security.md, "Flooding").
  static constexpr double kBlocksPerPeriod = 2.0;
  static constexpr double kBlockBurst = 40.0;
  double block_tokens = kBlockBurst;
  std::uint64_t blocks_over_rate = 0;
  std::uint64_t block_gaps = 0;        // blocks missing or out of order (within an incarnation)
  std::uint64_t sample_gaps = 0;       // samples missing between consecutive blocks (within one)
  std::uint64_t rejoins = 0;           // new incarnations seen
  std::uint64_t command_seq = 0;
  double last_friction_kN = 0.0;       // the calibrator's friction estimate at the last sample (sent with commands)
  std::uint64_t calibration_version = 0;
  std::uint64_t published_fits = 0;
  std::uint64_t published_restarts = 0;
  std::uint64_t deadlines_missed = 0;  // deadline-missed link events for this corner
  std::uint64_t liveliness_lost = 0;   // liveliness-lost link events for this corner's writer
  bool finished = false;               // received the last block
  bool have_writer = false;
  transport::EndpointId writer = 0;    // the current incarnation's measurement writer
  bool writer_left = false;            // that writer is gone (not only its lease lapsed)
  int health = -1;
  std::uint32_t health_incarnation = 0;
  std::array<faults::Diagnosis, 5> seen{};  // last diagnoses recorded (detection log)
};

// What the CCU reads from a received sample (the one conversion of the wire sample to the
// supervisor's reading; the force command only when the corner is in force mode).
faults::CornerReading reading_from(const msg::MeasurementSample& sample);

class CcuObserver {
 public:
  virtual ~CcuObserver() = default;
  // One received sample and what the CCU concluded from it.
  virtual void on_sample(const CornerChannel& channel, std::uint64_t block_seq, const msg::MeasurementSample& sample,
                         const SampleOutcome& outcome, const faults::CornerView& view, bool accepted) = 0;
  // The commands of one period (not for re-sends and the stop command).
  virtual void on_commands(double time_s, double demand_total_kN, double command_total_kN,
                           const std::array<CornerPlan, ccu::kSlots>& plans, const CcuCore& core) = 0;
};

class CcuNode {
 public:
  // Throws std::invalid_argument (corner names not FL/FR/RL/RR, twice, bad configs, period ratio).
  // `monitor` and `policy` go to CcuCore (defaults: the product's).
  CcuNode(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator, bool friction_feedback,
          const faults::MonitorParams& monitor = {}, ccu::ReactionPolicy policy = {});
  CcuNode(const CcuNode&) = delete;
  CcuNode& operator=(const CcuNode&) = delete;

  void set_observer(CcuObserver* observer) { observer_ = observer; }
  // The run this CCU belongs to (bbw_launch's run id; 0 in process): stamped on commands and
  // calibration states; blocks and health of another run are dropped and counted.
  void set_run_id(std::uint64_t run_id) { run_id_ = run_id; }
  std::uint64_t run_id() const { return run_id_; }
  std::uint64_t foreign_run_samples() const { return foreign_run_samples_; }

  // Inputs, per corner channel (the adapter knows which corner's partition it read from).
  void on_block(std::size_t channel, const msg::MeasurementBlock& block, transport::EndpointId writer, double arrival_s);
  void on_health(std::size_t channel, const msg::CornerHealth& health);
  // Link events from the transport (deadline missed on the corner's instance; its writer lost
  // or recovered). Lockstep only counts them (time is simulated; tick() finds a silent corner,
  // and a lost writer is acted on at the period's end, end_lockstep_period()).
  void on_deadline_missed(std::size_t channel, double time_s, bool lockstep);
  // How a writer was lost: it left (its participant's lease ran out, or it was deleted), or its
  // own liveliness lease lapsed (a lost link in real time: faults::LinkEvent::LeaseLapsed).
  enum class WriterLoss : std::uint8_t { Left, LeaseLapsed };
  void on_writer_lost(std::size_t channel, transport::EndpointId writer, double time_s, bool lockstep,
                      WriterLoss how);
  void on_writer_recovered(std::size_t channel, transport::EndpointId writer);
  // Lockstep: a restarted corner has announced itself; its block is expected from now on.
  void expect_rejoin(std::size_t channel);

  // A vehicle run (issue 15): the brake functions' clamp-force commands (CcuCore::set_brake_commands).
  void set_brake_commands(const std::array<std::optional<double>, ccu::kSlots>& clamp_force_kN) {
    core_.set_brake_commands(clamp_force_kN);
  }
  void set_curve_feedback(const std::optional<calibration::Curve>& curve) { core_.set_curve_feedback(curve); }
  // Further lockstep participants (the vehicle, the pedal): each reports the periods it finished;
  // one whose writer is gone no longer holds the barrier.
  std::size_t add_participant(const std::string& name) { return barrier_.add(name); }
  void participant_done(std::size_t participant, std::uint64_t step) { barrier_.done(participant, step); }
  void participant_alive(std::size_t participant, bool alive) { barrier_.set_alive(participant, alive); }

  // Outputs. The commands for period `step` (or the stop command), one per corner; `log` tells
  // the observer (not for re-sends).
  const std::vector<msg::ClampCommand>& commands(std::uint64_t step, bool stop, bool log = true);
  // Each corner's calibration state at version 0 (thresholds and initial curve, before period 0).
  const std::vector<msg::CalibrationState>& initial_states();
  // Calibration states to publish after the samples processed since the last clear (a fit was
  // accepted, or a calibrator restarted): the newest per corner, in memory kept per corner.
  const std::vector<const msg::CalibrationState*>& calibration_updates() const { return updates_; }
  void clear_calibration_updates() { updates_.clear(); }

  // The period's end: refill the flood guard, tick the supervisors, log new detections.
  void after_period(double now_s);
  void record_detections();

  // Lockstep: every corner's block `k` is in (or its writer is gone, or one reported failure).
  bool period_complete(std::uint64_t k) const { return barrier_.complete(k); }
  // Lockstep, after the wait for period k: a corner whose writer is gone without its block is
  // lost (LivelinessLost at t_end). Returns the name of a corner that reported failure, or "".
  std::string end_lockstep_period(std::uint64_t k, double t_end_s);
  std::string lagging(std::uint64_t k) const { return barrier_.lagging(k); }
  // Realtime end: every corner whose writer is still there has sent its last block (a corner
  // with a network finding, e.g. late under load, is still waited for; a lost writer is not).
  bool all_linked_finished() const;

  std::size_t channels() const { return channels_.size(); }
  CornerChannel& channel(std::size_t i) { return channels_[i]; }
  const CornerChannel& channel(std::size_t i) const { return channels_[i]; }
  // The channel of a wire corner id; nullptr for a corner not in the run.
  const CornerChannel* channel_of(std::uint8_t wire_id) const;
  const CcuCore& core() const { return core_; }
  std::uint64_t periods() const { return periods_; }
  // Simulated start and end of period k, as every adapter must compute them (k T, then + T:
  // the rounding is part of the lockstep's reproducibility).
  double period_start_s(std::uint64_t k) const { return static_cast<double>(k) * scenario_.ccu_period_s; }
  double period_end_s(std::uint64_t k) const { return period_start_s(k) + scenario_.ccu_period_s; }
  std::uint64_t unknown_corner_blocks() const { return unknown_corner_blocks_; }
  const std::vector<DetectionRecord>& detections() const { return detections_; }

 private:
  void publish_calibration(CornerChannel& ch, double time_s);

  const scenario::Scenario& scenario_;
  CcuCore core_;
  bool friction_feedback_;
  std::uint64_t periods_;
  LockstepBarrier barrier_;               // before channels_: make_channels adds the participants
  std::vector<CornerChannel> channels_;
  std::vector<msg::ClampCommand> commands_;
  std::vector<msg::CalibrationState> states_;            // one per channel, reused (no allocation per fit)
  std::vector<const msg::CalibrationState*> updates_;
  std::vector<msg::CalibrationState> initial_;
  std::vector<DetectionRecord> detections_;
  std::uint64_t unknown_corner_blocks_ = 0;
  std::uint64_t run_id_ = 0;
  std::uint64_t foreign_run_samples_ = 0;  // blocks and health of another run, dropped unread
  CcuObserver* observer_ = nullptr;
};

}  // namespace bbw::node
