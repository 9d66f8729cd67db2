#include "bbw/node/ccu_node.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "bbw/dds/convert.hpp"
#include "bbw/node/corner_node.hpp"

namespace bbw::node {

namespace {

std::vector<CornerChannel> make_channels(const scenario::Scenario& s, LockstepBarrier& barrier) {
  std::vector<CornerChannel> out;
  for (const auto& c : s.corners) {
    const auto corner = parse_corner(c.name);  // CcuCore has checked the names
    if (!corner) throw std::invalid_argument(s.file + ": corner '" + c.name + "' is not FL, FR, RL or RR");
    CornerChannel ch;
    ch.corner = *corner;
    ch.slot = corner_index(*corner);
    ch.barrier = barrier.add(c.name);
    out.push_back(std::move(ch));
  }
  steps_per_period(s);  // throws unless the period ratio fits a block
  return out;
}

}  // namespace

faults::CornerReading reading_from(const msg::MeasurementSample& s) {
  faults::CornerReading r;
  r.seq = s.seq();
  r.time_s = s.time_s();
  r.position_rev = s.position_rev();
  r.speed_rev_per_s = s.speed_rev_per_s();
  r.force_kN = s.force_internal_kN();
  r.motor_current_A = s.motor_current_A();
  r.temperature_C = s.temperature_C();
  r.force_command_kN = (s.status() & msg::STATUS_FORCE_MODE) ? s.command() : std::nan("");
  return r;
}

namespace {

std::uint8_t feedback_code(const std::optional<corner_unit::ForceFeedback>& f) {
  if (!f) return msg::FEEDBACK_OWN;
  return *f == corner_unit::ForceFeedback::Curve ? msg::FEEDBACK_CURVE : msg::FEEDBACK_LOAD_CELL;
}

}  // namespace

CcuNode::CcuNode(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
                 bool friction_feedback, const faults::MonitorParams& monitor, ccu::ReactionPolicy policy)
    : scenario_(scenario),
      core_(scenario, calibrator, monitor, policy),
      friction_feedback_(friction_feedback),
      periods_(periods_of(scenario)),
      channels_(make_channels(scenario, barrier_)) {
  commands_.resize(channels_.size());
  states_.resize(channels_.size());
  for (auto& s : states_) {
    s.friction_delta_rev().reserve(msg::MAX_FRICTION_ELEMENTS);
    s.friction_stiffness_kN_per_rev().reserve(msg::MAX_FRICTION_ELEMENTS);
  }
  updates_.reserve(channels_.size());
  detections_.reserve(256);
}

const CornerChannel* CcuNode::channel_of(std::uint8_t wire_id) const {
  for (const auto& ch : channels_) {
    if (corner_index(ch.corner) == wire_id) return &ch;
  }
  return nullptr;
}

void CcuNode::on_health(std::size_t i, const msg::CornerHealth& h) {
  CornerChannel& ch = channels_[i];
  if (h.run_id() != run_id_) {
    ++foreign_run_samples_;  // another run's (dropped unread)
    return;
  }
  if (h.corner_id() != ch.slot) {
    ++ch.foreign_health;  // another corner id in this corner's partition
    return;
  }
  if (h.incarnation() < ch.health_incarnation) return;  // an older process's last word
  ch.health_incarnation = h.incarnation();
  ch.health = h.status();
  barrier_.set_failed(ch.barrier, ch.health == msg::HEALTH_FAILED);
}

const std::vector<msg::ClampCommand>& CcuNode::commands(std::uint64_t step, bool stop, bool log) {
  const double t = static_cast<double>(step) * scenario_.ccu_period_s;
  const auto& plans = core_.plan(t);
  double total = 0.0;
  // Overwritten in place, every field each time: constructing a message re-registers the
  // generated TypeObject (a map search under a lock), the CCU's largest cost per period.
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    CornerChannel& ch = channels_[i];
    const CornerPlan& p = plans[ch.slot];
    msg::ClampCommand& c = commands_[i];
    c.corner_id(static_cast<std::uint8_t>(ch.slot));
    c.run_id(run_id_);
    c.seq(ch.command_seq++);
    c.step(step);
    c.time_s(t);
    c.mode(p.mode == ccu::CommandMode::Force ? msg::MODE_FORCE : msg::MODE_PROFILE);
    c.clamp_force_kN(p.clamp_force_kN);
    c.valid(!stop);
    c.use_friction_comp(friction_feedback_);
    c.calibration_version(ch.calibration_version);
    c.friction_estimate_kN(ch.last_friction_kN);
    c.stop(stop);
    c.feedback_override(feedback_code(p.feedback));
    c.override_curve_a_kN_per_rev3(p.curve.a);
    c.override_curve_b_kN_per_rev2(p.curve.b);
    c.override_curve_c_kN_per_rev(p.curve.c);
    c.override_curve_d_kN(p.curve.d);
    if (p.mode == ccu::CommandMode::Force) total += p.clamp_force_kN;
  }
  if (observer_ != nullptr && !stop && log) observer_->on_commands(t, core_.demand_total_kN(t), total, plans, core_);
  return commands_;
}

const std::vector<msg::CalibrationState>& CcuNode::initial_states() {
  initial_.clear();
  for (auto& ch : channels_) {
    msg::CalibrationState& s = initial_.emplace_back();
    // A calibrator that starts from its caliper's measured keys (calibrator_start.friction_from_
    // end_of_line) has a model worth compensating with from the first sample: its initial state is
    // version 1, which a corner on compensated feedback uses. Without it, the corners held their
    // load cells at the command until a first fit, which a hold never brings, and the clamp force
    // stood the keys' 0.9 kN below it (dry_gentle_stop_100kmh: 3.44 kN for 4.31 commanded).
    const calibration::Calibrator& cal = core_.supervisor(ch.slot).calibrator();
    ch.calibration_version = cal.prior_friction_fitted() ? 1 : 0;
    dds::to_msg(cal, static_cast<std::uint8_t>(ch.slot), ch.calibration_version, 0.0, s);
    s.run_id(run_id_);
  }
  return initial_;
}

void CcuNode::publish_calibration(CornerChannel& ch, double time_s) {
  const faults::CornerSupervisor& sup = core_.supervisor(ch.slot);
  const auto fits = sup.calibrator().stats().fits_accepted;
  const auto restarts = sup.calibrator_restarts();
  if (fits == ch.published_fits && restarts == ch.published_restarts) return;
  // A fit was accepted, or the calibrator restarted from the last good curve (a rejoin).
  ch.published_fits = fits;
  ch.published_restarts = restarts;
  ++ch.calibration_version;
  msg::CalibrationState& state = states_[static_cast<std::size_t>(&ch - channels_.data())];
  dds::to_msg(sup.calibrator(), static_cast<std::uint8_t>(ch.slot), ch.calibration_version, time_s, state);
  state.run_id(run_id_);
  if (std::find(updates_.begin(), updates_.end(), &state) == updates_.end()) updates_.push_back(&state);
}

void CcuNode::on_block(std::size_t i, const msg::MeasurementBlock& b, transport::EndpointId writer, double arrival_s) {
  CornerChannel& ch = channels_[i];
  if (b.run_id() != run_id_) {
    ++foreign_run_samples_;  // another run's block: dropped before anything reads it or its rate
    return;
  }
  if (ch.block_tokens < 1.0) {
    ++ch.blocks_over_rate;  // beyond the corner's rate: dropped unread
    return;
  }
  ch.block_tokens -= 1.0;
  if (b.corner_id() != ch.slot) {
    // Another corner id in this corner's partition: a corner posing as another (or as one
    // that does not exist). Dropped and counted before anything reads it.
    ++ch.foreign_blocks;
    if (channel_of(b.corner_id()) == nullptr) ++unknown_corner_blocks_;
    return;
  }
  if (!ch.have_writer || ch.writer != writer) {
    ch.writer = writer;
    ch.have_writer = true;
    ch.writer_left = false;
    barrier_.set_alive(ch.barrier, true);
  }
  if (b.incarnation() != ch.incarnation) {
    // A restarted process: its block and sample numbering start where it joined.
    ch.incarnation = b.incarnation();
    barrier_.rejoin(ch.barrier, b.block_seq());
    ch.next_sample_seq = b.samples().empty() ? 1 : b.samples().front().seq();
    ++ch.rejoins;
    core_.on_link_event(ch.slot, faults::LinkEvent::Restarted, arrival_s);
  }
  if (b.block_seq() != barrier_.next(ch.barrier)) ++ch.block_gaps;
  // Never backwards within an incarnation: an old or forged block number cannot make the
  // lockstep clock wait again for a block it already has.
  barrier_.done(ch.barrier, b.block_seq());
  ++ch.blocks_received;
  if (!b.samples().empty() && b.samples().front().seq() != ch.next_sample_seq) {
    ch.sample_gaps += b.samples().front().seq() > ch.next_sample_seq ? b.samples().front().seq() - ch.next_sample_seq : 1;
  }
  for (const auto& s : b.samples()) {
    ++ch.samples_received;
    ch.next_sample_seq = s.seq() + 1;
    const faults::CornerReading r = reading_from(s);
    const std::uint64_t rejected_before = core_.supervisor(ch.slot).guard().rejected();
    const SampleOutcome& o = core_.on_sample(ch.slot, r, arrival_s);
    const bool accepted = core_.supervisor(ch.slot).guard().rejected() == rejected_before;
    if (!accepted) ++ch.samples_invalid;
    if (o.valid && o.from_calibrator) ch.last_friction_kN = o.friction_kN;
    if (observer_ != nullptr) observer_->on_sample(ch, b.block_seq(), s, o, core_.supervisor(ch.slot).view(), accepted);
  }
  if (b.block_seq() + 1 >= periods_) ch.finished = true;
  publish_calibration(ch, b.samples().empty() ? arrival_s : b.samples().back().time_s());
}

// A corner that has sent its last block is done: its deadline passing and its writer leaving
// are its normal end (they raised link_lost and process_lost on the corners that finished first
// while the CCU still waited for another's last block).
void CcuNode::on_deadline_missed(std::size_t i, double time_s, bool lockstep) {
  CornerChannel& ch = channels_[i];
  if (!ch.have_writer || ch.finished) return;
  ++ch.deadlines_missed;
  if (!lockstep) core_.on_link_event(ch.slot, faults::LinkEvent::DeadlineMissed, time_s);
}

void CcuNode::on_writer_lost(std::size_t i, transport::EndpointId writer, double time_s, bool lockstep, WriterLoss how) {
  CornerChannel& ch = channels_[i];
  if (!ch.have_writer || ch.finished || writer != ch.writer) return;
  const bool was_alive = barrier_.alive(ch.barrier);
  if (how == WriterLoss::LeaseLapsed) {
    // Real time: a lapse is a lost link until the writer leaves or a new process joins (a corner
    // never killed was once named process_lost in SystemFaultsRealtime's restart test, beside the
    // restarting one). Lockstep: the writer is taken as gone, as before (its 2 s lease).
    if (!was_alive) return;
    ++ch.liveliness_lost;
    barrier_.set_alive(ch.barrier, false);
    if (!lockstep) core_.on_link_event(ch.slot, faults::LinkEvent::LeaseLapsed, time_s);
    return;
  }
  // Gone: also after a lapse (its link already lost), but once per writer.
  if (ch.writer_left) return;
  ch.writer_left = true;
  if (was_alive) ++ch.liveliness_lost;
  barrier_.set_alive(ch.barrier, false);
  if (!lockstep) core_.on_link_event(ch.slot, faults::LinkEvent::LivelinessLost, time_s);
}

void CcuNode::on_writer_recovered(std::size_t i, transport::EndpointId writer) {
  CornerChannel& ch = channels_[i];
  if (!ch.have_writer || ch.finished || writer != ch.writer) return;
  barrier_.set_alive(ch.barrier, true);
}

void CcuNode::expect_rejoin(std::size_t i) { barrier_.set_alive(channels_[i].barrier, true); }

void CcuNode::record_detections() {
  for (auto& ch : channels_) {
    const faults::FaultMonitor& m = core_.supervisor(ch.slot).monitor();
    for (std::size_t p = 0; p < ch.seen.size(); ++p) {
      const faults::Diagnosis& d = m.diagnosis(static_cast<faults::Part>(p));
      faults::Diagnosis& seen = ch.seen[p];
      // A finding upgraded later (e.g. actuator_lost -> actuator_not_releasing) is recorded at
      // the time of the upgrade.
      if (d.present && (!seen.present || d.detected_s != seen.detected_s || d.finding != seen.finding)) {
        if (detections_.size() < detections_.capacity()) detections_.push_back({ch.slot, d.finding, d.onset_s, d.finding_s});
      }
      seen = d;
    }
  }
}

void CcuNode::after_period(double now_s) {
  for (auto& ch : channels_) {
    ch.block_tokens = std::min(CornerChannel::kBlockBurst, ch.block_tokens + CornerChannel::kBlocksPerPeriod);
  }
  core_.tick(now_s);
  record_detections();
}

std::string CcuNode::end_lockstep_period(std::uint64_t k, double t_end_s) {
  std::string failed;
  for (auto& ch : channels_) {
    if (ch.health == msg::HEALTH_FAILED) {
      if (failed.empty()) failed = corner_name(ch.corner);
    } else if (barrier_.next(ch.barrier) <= k && !barrier_.alive(ch.barrier)) {
      core_.on_link_event(ch.slot, faults::LinkEvent::LivelinessLost, t_end_s);
    }
  }
  return failed;
}

bool CcuNode::all_linked_finished() const {
  // Waited for: every corner whose writer is there (seen and not lost) and has not yet sent its
  // last block, whatever the monitor thinks of its link. A corner late beyond its deadline on a
  // loaded machine has a network finding but is still sending: before, the end did not wait for
  // it and its last blocks went unreceived (CcuNodeEnd.*).
  for (const auto& ch : channels_) {
    if (!ch.finished && ch.have_writer && barrier_.alive(ch.barrier)) return false;
  }
  return true;
}

}  // namespace bbw::node
