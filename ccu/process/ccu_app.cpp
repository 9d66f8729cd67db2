#include "ccu_app.hpp"

#include "bbw/dds/receive_runner.hpp"

#include <cstdlib>

#include <signal.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <stdexcept>

#include "bbw/dds/run_id.hpp"
#include "bbw/dds/topics.hpp"
#include "bbw/faults/link_faults.hpp"
#include "bbw/runtime/period_clock.hpp"
#include "bbw/runtime/run_stats.hpp"
#include "bbw/node/csv_log.hpp"
#include "bbw/security/dds_security.hpp"

namespace bbw::ccu {

namespace {

using Clock = std::chrono::steady_clock;

dds::ParticipantOptions named(dds::ParticipantOptions p, const CcuOptions& o) {
  if (p.name.empty()) p.name = o.standby && o.role == "standby" ? "bbw_ccu_standby" : "bbw_ccu";
  return p;
}

// A standby run's lockstep re-send interval: the corners' command deadline (10 ms), so the
// standby's grant reaches a corner soon after the corner dropped a silent primary.
constexpr auto kStandbyResend = std::chrono::milliseconds(10);
// A CCU whose own commands were this far apart may have lost the corners' ownership to the other
// CCU for a moment (a stall): the command deadline of the *_owned profiles.
constexpr double kOwnershipDeadline_s = 0.010;
// A CCU that heard no block from any corner this long is cut off (its link is down): longer than
// the measurement deadline (15 ms), so one late period of every corner is not a cut.
constexpr double kCutOff_s = 0.050;
// After a long outage (continued after a stop, or its link back after a cut) a CCU sends no
// command for this long: its state is stale, and its lowered strength must reach every corner
// first. Fast DDS sends the strength by discovery, which a cut link delays: the corners took the
// primary back for 550 ms after its link returned before they had its lowered strength.
constexpr auto kRejoinQuiet = std::chrono::milliseconds(1000);


// The first period that starts at or after time_s.
std::uint64_t step_at(double time_s, double period_s) {
  return static_cast<std::uint64_t>(std::max(0.0, std::ceil(time_s / period_s - 1e-9)));
}

}  // namespace

CcuApp::CcuApp(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
               const CcuOptions& options, dds::Events& events)
    : scenario_(scenario),
      options_(options),
      events_(events),
      node_(scenario, calibrator, options.friction_feedback, options.monitor),
      periods_(node_.periods()),
      participant_(named(options.participant, options)),
      // Calibration state in the run's partition; measurements, health and each corner's commands
      // in that corner's partition of this run (bbw/dds/run_id.hpp): another run on the domain
      // never matches, and a corner is woken only by its own command (not by all four).
      calibration_(participant_, dds::kCalibrationTopic, "state_writer", events,
                   dds::Partition{dds::run_partition(options.participant.run_id)}) {
  node_.set_run_id(options.participant.run_id);
  for (std::size_t i = 0; i < node_.channels(); ++i) {
    const dds::Partition partition{dds::corner_run_partition(
        security::corner_partition(static_cast<int>(node_.channel(i).slot)), options.participant.run_id)};
    blocks_.push_back(std::make_unique<BlockInlet>(
        participant_, dds::kMeasurementTopic,
        dds::profiles_for(options.mode == ClockMode::Lockstep, options.standby).measurement_reader, events, partition));
    health_.push_back(std::make_unique<HealthInlet>(participant_, dds::kHealthTopic, "state_reader", events, partition));
    commands_.push_back(std::make_unique<CommandOutlet>(
        participant_, dds::kCommandTopic, dds::profiles_for(options.mode == ClockMode::Lockstep, options.standby).command_writer, events,
        partition));
  }
  instances_.resize(node_.channels());
  if (options.standby && options.mode == ClockMode::Lockstep) {
    stash_.resize(node_.channels());
    for (Stash& s : stash_) {
      for (Stash::Slot& slot : s.slots) slot.block.samples().reserve(msg::MAX_BLOCK_SAMPLES);
    }
  }
  const faults::Target self = options.standby && options.role == "standby" ? faults::Target::CcuStandby : faults::Target::CCU;
  if (options.standby) {
    failover_.role = options.role;
    failover_.strength_initial = dds::ccu_strength(options.role != "standby", 0);
    set_strength(failover_.strength_initial);
  }
  block_.samples().reserve(msg::MAX_BLOCK_SAMPLES);
  if (options.vehicle != nullptr) {
    const dds::Partition run{dds::run_partition(options.participant.run_id)};
    vehicle_in_ = std::make_unique<dds::DdsInlet<msg::VehicleSensorsPubSubType>>(
        participant_, dds::kVehicleSensorsTopic, dds::profiles_for(true).measurement_reader, events, run);
    pedal_in_ = std::make_unique<dds::DdsInlet<msg::PedalSamplePubSubType>>(
        participant_, dds::kPedalTopic, dds::profiles_for(true).measurement_reader, events, run);
    vehicle_participant_ = node_.add_participant("vehicle");
    pedal_participant_ = node_.add_participant("pedal");
    vehicle::Vehicle v(options.vehicle->vehicle.vehicle, options.vehicle->road);
    v.reset(options.vehicle->initial_speed_m_s, options.vehicle->disc_C, options.vehicle->caliper_C);
    brake_.emplace(options.vehicle->brake, scenario.ccu_period_s, v.state());
  }
  if (options.process_faults) {
    for (const faults::ProcessAction& a : faults::process_actions(options.schedule)) {
      if (faults::is_ccu(a.target)) {
        if (a.target != self) continue;  // the other CCU's
        if (a.kind == faults::ProcessAction::Kind::Kill && !kill_at_s_) kill_at_s_ = a.at_s;
        if (a.kind == faults::ProcessAction::Kind::Hang && !hang_at_s_) hang_at_s_ = a.at_s;
      } else if (a.kind == faults::ProcessAction::Kind::Restart) {
        restarts_.emplace_back(step_at(a.at_s, scenario.ccu_period_s), *faults::corner_slot(a.target));
      }
    }
  }
  if (options.out_dir.empty()) return;
  log_ = std::make_unique<node::CcuCsvLog>(options.out_dir, node_);
  node_.set_observer(log_.get());
}

CcuApp::~CcuApp() {
  node_.set_observer(nullptr);
  vehicle_in_.reset();
  pedal_in_.reset();
  // The readers go before the participant (members are destroyed after this body).
  blocks_.clear();
  health_.clear();
  commands_.clear();
}

double CcuApp::realtime_now_s() const { return std::chrono::duration<double>(Clock::now() - t0_).count(); }

void CcuApp::drain_health() {
  msg::CornerHealth& h = health_in_;  // a member: a message's default constructor re-registers its TypeObject
  for (std::size_t i = 0; i < node_.channels(); ++i) {
    while (health_[i]->take(h)) node_.on_health(i, h);
  }
}

// A lockstep CCU that has left the run stays matched until the corners are done (their block
// writers gone) or the peer timeout, taking and dropping what they send. Its readers leaving while
// the corners still ran made a corner's writer remove a matched reader while that writer's
// flow-controller thread was sending to it, which can deadlock Fast DDS 2.9: the lock-order
// inversion between StatefulWriter::matched_reader_remove and the flow controller's thread of
// eProsima/Fast-DDS#3468 and #5432 (the latter merged in 2024 for 2.10 and later). Seen once in the
// system set beside a sanitizer build, SystemFailover.HungPrimaryLockstepLeavesTheRun: the
// front-right corner hung in DataWriter::write (gdb of the live process) and the run stalled to
// its bound.
void CcuApp::linger_until_corners_done() {
  transport::EndpointId writer = 0;
  events_.wait_until(Clock::now() + options_.peer_timeout, [&] {
    bool matched = false;
    for (auto& b : blocks_) {
      while (b->take(block_, writer)) {
      }
      matched = matched || b->peers() > 0;
    }
    msg::CornerHealth& h = health_in_;
    for (auto& r : health_) {
      while (r->take(h)) {
      }
    }
    return !matched;
  });
}

// A vehicle run: the vehicle's and the pedal's period reports into the brake functions and the barrier.
void CcuApp::drain_vehicle() {
  if (!brake_) return;
  while (vehicle_in_->take(vehicle_msg_)) {
    if (vehicle_msg_.run_id() != options_.participant.run_id) continue;
    brake_->on_vehicle(vehicle_msg_);
    node_.participant_done(vehicle_participant_, vehicle_msg_.step());
  }
  while (pedal_in_->take(pedal_msg_)) {
    if (pedal_msg_.run_id() != options_.participant.run_id) continue;
    brake_->on_pedal(pedal_msg_);
    node_.participant_done(pedal_participant_, pedal_msg_.step());
  }
}

bool CcuApp::wait_for_corners(std::string& error) {
  const int n = static_cast<int>(node_.channels());
  const bool ok = events_.wait_for(options_.discovery_timeout, [&] {
    drain_health();
    bool all = calibration_.peers() >= n;
    for (const auto& c : commands_) all = all && c->peers() >= 1;
    for (std::size_t i = 0; i < node_.channels(); ++i) all = all && node_.channel(i).health >= 0 && blocks_[i]->peers() >= 1;
    if (brake_) {
      all = all && vehicle_in_->peers() >= 1 && pedal_in_->peers() >= 1;
      // The pedal reads the front-left corner's commands (its grants).
      for (std::size_t i = 0; i < node_.channels(); ++i) {
        if (node_.channel(i).slot == 0) all = all && commands_[i]->peers() >= 2;
      }
    }
    return all;
  });
  if (!ok && !events_.interrupted()) {
    int matched_blocks = 0;
    for (const auto& r : blocks_) matched_blocks += r->peers() >= 1 ? 1 : 0;
    std::string missing;
    for (std::size_t i = 0; i < node_.channels(); ++i) {
      if (node_.channel(i).health < 0) missing += (missing.empty() ? "" : ", ") + std::string(corner_name(node_.channel(i).corner));
    }
    error = "corners not discovered within " + std::to_string(options_.discovery_timeout.count()) +
            " ms: " + (missing.empty() ? std::string("(endpoints incomplete)") : missing) +
            " (measurement writers matched " + std::to_string(matched_blocks) + " of " + std::to_string(n) + ")";
  }
  return ok;
}

void CcuApp::send_commands(std::uint64_t step, bool stop, bool log) {
  // The node's commands are in channel order, as commands_.
  const auto& cmds = node_.commands(step, stop, log);
  // Realtime, cut off or back from an outage: nothing. A command written while cut off would
  // reach the corners when the link returns, before the lowered strength does, and they would
  // take it (seen: FL applied such a command, computed with every corner lost, 0 kN, for 25 ms).
  // Lockstep never: its commands are the grants the corners wait for, the two CCUs' are the same,
  // and a corner takes none for a period it has done (both CCUs silent once deadlocked a run).
  if (options_.standby && options_.mode == ClockMode::Realtime && !stop && (cut_off_ || Clock::now() < quiet_until_)) {
    return;
  }
  for (std::size_t i = 0; i < cmds.size(); ++i) commands_[i]->send(cmds[i]);
}

// dds::ccu_strength, 1 lower per re-announcement after a cut (at most 999: the order of the two
// CCUs, steps of 1000, never changes by it).
std::uint32_t CcuApp::strength() const {
  return dds::ccu_strength(options_.role != "standby", failover_.outages) - std::min<std::uint32_t>(reannouncements_, 999);
}

void CcuApp::set_strength(std::uint32_t strength) {
  for (auto& c : commands_) {
    auto& w = c->get().get();
    eprosima::fastdds::dds::DataWriterQos q = w.get_qos();
    q.ownership_strength().value = strength;
    if (w.set_qos(q) != ReturnCode_t::RETCODE_OK) {
      throw dds::DdsError("cannot set the command writer's ownership strength to " + std::to_string(strength));
    }
  }
  failover_.strength_final = strength;
}

void CcuApp::demote(double sim_s, const char* reason) {
  if (!options_.standby) return;
  ++failover_.outages;
  set_strength(strength());
  failover_.demoted_sim_s = sim_s;
  failover_.demoted_mono_s = runtime::mono_now_s();
  failover_.demote_reason = reason;
  std::cout << "bbw_ccu (" << options_.role << "): lowered its command strength to " << failover_.strength_final
            << " at " << sim_s << " s (" << reason << ")" << std::endl;
}

// Cut off: the commands written since the link went down wait in the writers' reliable histories
// and would be delivered when it returns, stale. The corners drop them, but DDS ownership would
// already have passed to this writer, whose lowered strength may not have reached them yet, and
// the other CCU's commands would not be let through until this writer missed its deadline (a
// -j2 system pass: 25 ms without a command and the corners' safe state, just after the link
// returned, with the standby never stalled). So they are discarded here.
void CcuApp::discard_unsent_commands() {
  for (auto& c : commands_) {
    std::size_t removed = 0;
    if (c->get().get().clear_history(&removed) != ReturnCode_t::RETCODE_OK) {
      throw dds::DdsError("cannot clear the command writer's history after a cut");
    }
    commands_discarded_ += removed;
  }
  std::cout << "bbw_ccu (" << options_.role << "): discarded " << commands_discarded_
            << " commands unsent since the cut (they would arrive stale)" << std::endl;
}

// The link is back after a cut: quiet for kRejoinQuiet, and the lowered strength announced again
// (set while cut off, its discovery message may not have reached the corners: once they kept the
// returned primary as the owner for the rest of the run). A strength 1 lower is a new value, so
// Fast DDS announces it now; the order of the two CCUs (steps of 1000) does not change.
void CcuApp::link_back() {
  quiet_until_ = Clock::now() + kRejoinQuiet;
  ++reannouncements_;
  set_strength(strength());
}

void CcuApp::write_failover_stats() const {
  if (!options_.standby || options_.out_dir.empty()) return;
  runtime::CcuFailoverStats s = failover_;
  s.periods_done = periods_done_;
  runtime::save(s, options_.out_dir + "/ccu_failover.stats");
}

void CcuApp::send_calibration_updates() {
  for (const msg::CalibrationState* s : node_.calibration_updates()) calibration_.send(*s);
  node_.clear_calibration_updates();
}

void CcuApp::drain_blocks(double arrival_s, std::optional<std::uint64_t> step) {
  const bool realtime = options_.mode == ClockMode::Realtime;
  transport::EndpointId writer = 0;
  if (step && options_.standby) {
    drain_blocks_in_order(arrival_s, *step);
    return;
  }
  for (std::size_t i = 0; i < node_.channels(); ++i) {
    while (blocks_[i]->take(block_, writer)) {
      last_block_at_ = Clock::now();
      if (cut_off_) link_back();
      cut_off_ = false;
      if (block_.corner_id() == node_.channel(i).slot) instances_[i] = blocks_[i]->last_info().instance_handle;
      node_.on_block(i, block_, writer, realtime ? realtime_now_s() : arrival_s);
      send_calibration_updates();
    }
  }
}

// Lockstep with a hot-standby CCU: the corners follow the grants of whichever CCU owns their
// commands, so this CCU may be behind them (it started later, or it is slower) and find blocks
// of later periods waiting. It takes them into the node in period order, each in its own period:
// the two CCUs then compute the same thing from the same blocks whoever leads. The blocks of
// later periods wait in a stash sized at construction.
void CcuApp::drain_blocks_in_order(double arrival_s, std::uint64_t step) {
  for (std::size_t i = 0; i < node_.channels(); ++i) {
    Stash& s = stash_[i];
    auto process = [&](const msg::MeasurementBlock& b, transport::EndpointId writer) {
      last_block_at_ = Clock::now();
      if (cut_off_) link_back();
      cut_off_ = false;
      node_.on_block(i, b, writer, arrival_s);
      send_calibration_updates();
    };
    while (s.count > 0 && s.slots[s.head].block.block_seq() <= step) {
      process(s.slots[s.head].block, s.slots[s.head].writer);
      s.head = (s.head + 1) % s.slots.size();
      --s.count;
    }
    transport::EndpointId writer = 0;
    while (blocks_[i]->take(block_, writer)) {
      if (block_.corner_id() == node_.channel(i).slot) instances_[i] = blocks_[i]->last_info().instance_handle;
      // A corner's blocks come from one reliable writer, in order: a jump means the blocks between
      // are gone for good (this CCU was cut off longer than the corner's measurement history or
      // its discovery lease), and it could only wait for them until the peer timeout. Not with a
      // scheduled corner restart (a new writer that resumes at its own period), and only for the
      // channel's own corner of this run (anything else is dropped by the node unread).
      const bool own = block_.corner_id() == node_.channel(i).slot && block_.run_id() == options_.participant.run_id;
      if (own && s.last_seq && block_.block_seq() > *s.last_seq + 1 && restarts_.empty() && !fell_out_) {
        fell_out_ = true;
        fell_out_why_ = "blocks " + std::to_string(*s.last_seq + 1) + "-" + std::to_string(block_.block_seq() - 1) + " of " +
                        std::string(corner_name(node_.channel(i).corner)) + " never arrived";
      }
      if (own && (!s.last_seq || block_.block_seq() > *s.last_seq)) s.last_seq = block_.block_seq();
      if (block_.block_seq() <= step && s.count == 0) {
        process(block_, writer);
      } else if (s.count < s.slots.size()) {
        Stash::Slot& slot = s.slots[(s.head + s.count) % s.slots.size()];
        slot.block = block_;
        slot.writer = writer;
        ++s.count;
      } else {
        ++stash_overflows_;  // further behind than the stash holds: the block is lost to this CCU
        if (!fell_out_) {
          fell_out_ = true;
          fell_out_why_ = "more than " + std::to_string(s.slots.size()) + " periods behind " + std::string(corner_name(node_.channel(i).corner));
        }
      }
    }
  }
}

// QoS events into link events. Realtime: at the time they happened. Lockstep: deadlines are
// not used (time is simulated: CornerSupervisor::tick finds a silent corner), and a lost
// writer is acted on only while its corner's block is missing (node::CcuNode::end_lockstep_period),
// so a slow machine cannot change the result.
void CcuApp::drain_qos_events(double now_s, bool lockstep) {
  dds::QosEvent e;
  for (std::size_t i = 0; i < node_.channels(); ++i) {
    while (blocks_[i]->get().take_event(e)) {
      const double t = lockstep ? now_s : std::chrono::duration<double>(e.at - t0_).count();
      if (e.kind == dds::QosEvent::Kind::DeadlineMissed) {
        if (e.handle == instances_[i]) node_.on_deadline_missed(i, t, lockstep);
      } else if (e.kind == dds::QosEvent::Kind::LivelinessLost || e.kind == dds::QosEvent::Kind::WriterLost) {
        node_.on_writer_lost(i, dds::endpoint_id(e.handle), t, lockstep,
                             e.kind == dds::QosEvent::Kind::WriterLost ? node::CcuNode::WriterLoss::Left
                                                                       : node::CcuNode::WriterLoss::LeaseLapsed);
      } else if (e.kind == dds::QosEvent::Kind::LivelinessRecovered) {
        node_.on_writer_recovered(i, dds::endpoint_id(e.handle));
      }
    }
  }
  node_.record_detections();
}

bool CcuApp::wait_for_rejoin(std::size_t i, std::uint32_t incarnation, std::string& error) {
  const node::CornerChannel& ch = node_.channel(i);
  const bool ok = events_.wait_for(options_.discovery_timeout, [&] {
    drain_health();
    return ch.health_incarnation >= incarnation &&
           (ch.health == msg::HEALTH_STARTING || ch.health == msg::HEALTH_RUNNING);
  });
  if (ok) node_.expect_rejoin(i);  // its block is expected from now on
  if (!ok && !events_.interrupted()) {
    error = std::string("restarted corner ") + corner_name(ch.corner) + " did not join within " +
            std::to_string(options_.discovery_timeout.count()) + " ms";
  }
  return ok;
}

void CcuApp::freeze_for_kill(double at_s) {
  // The scheduled CCU kill: keep the logs up to this instant, then stop dead. From SIGSTOP on
  // nothing is sent (not even liveliness), as after a crash; the launcher SIGKILLs us.
  sim_s_ = at_s;
  wall_s_ = std::chrono::duration<double>(Clock::now() - t0_).count();
  if (log_ != nullptr) log_->flush();
  if (!options_.out_dir.empty()) write_stats(options_.out_dir + "/ccu.stats");
  failover_.failure = "kill";
  failover_.failed_sim_s = at_s;
  failover_.failed_mono_s = runtime::mono_now_s();
  write_failover_stats();
  ::raise(SIGSTOP);
  // Continued instead of killed (nobody carried the kill out): stop without a word.
  ::_exit(kExitRuntime);
}

void CcuApp::freeze_for_hang(double at_s) {
  // The scheduled hang (a standby run): stop dead like a kill, but the launcher leaves the
  // process stopped (and continues it after resume_after_s, if given).
  hang_at_s_.reset();
  if (log_ != nullptr) log_->flush();
  failover_.failure = "hang";
  failover_.failed_sim_s = at_s;
  failover_.failed_mono_s = runtime::mono_now_s();
  write_failover_stats();
  ::raise(SIGSTOP);
  failover_.resumed_mono_s = runtime::mono_now_s();
  demote(at_s, "resumed after a stop");
  quiet_until_ = Clock::now() + kRejoinQuiet;
}

int CcuApp::run(std::string& error) {
  if (!wait_for_corners(error)) return events_.interrupted() ? kExitOk : kExitDiscovery;
  // Initial model: every corner knows the thresholds and initial curve before period 0.
  for (const msg::CalibrationState& s : node_.initial_states()) calibration_.send(s);
  // The clock policy (bbw/runtime/period_clock.hpp): lockstep, period k begins when every
  // live corner's block k is in (commands re-sent on a stall); realtime, at t0 + k * T, inputs
  // drained as they come.
  const double T = scenario_.ccu_period_s;
  const auto clock = runtime::make_period_clock(
      options_.mode, events_, T, options_.peer_timeout, /*poll_while_waiting=*/true,
      options_.standby ? Clock::duration(kStandbyResend) : Clock::duration(std::chrono::milliseconds(200)));
  clock->start(0);
  t0_ = clock->started_at();
  failover_.t0_mono_s = std::chrono::duration<double>(t0_.time_since_epoch()).count();
  int rc = kExitOk;
  bool retired = false;
  std::uint32_t expected_incarnation[kSlots] = {};
  if (options_.mode == ClockMode::Lockstep) {
    // The periods run on the thread that receives their last block (run_on_receive) until
    // something needs this loop: a failure, the end, a stall. A standby run and scheduled
    // process faults stay on this loop throughout.
    const bool on_receive = !options_.standby && !kill_at_s_ && !hang_at_s_ && restarts_.empty() && dds::lockstep_on_receive();
    std::uint64_t k_from = 0;
    bool resumed = false;  // k_from's commands were sent on the receiving thread
    bool skip_loop = false;
    if (on_receive) {
      if (brake_) brake_->plan(node_);
      send_commands(0, false);
      next_k_ = 0;
      next_begun_ = true;  // period 0's commands were just sent
      const auto end = dds::run_on_receive(events_, [this] { return advance_on_receive(); }, [this] { return progress_; });
      if (!receive_failure_.empty()) {
        error = receive_failure_;
        rc = kExitPeerLost;
        skip_loop = true;
      } else if (end == dds::ReceiveRunEnd::Interrupted) {
        skip_loop = true;
      }
      k_from = next_k_;
      resumed = next_begun_;
    }
    for (std::uint64_t k = k_from; !skip_loop && k < periods_ && !events_.interrupted(); ++k) {
      const double t_k = node_.period_start_s(k);
      if (!(resumed && k == k_from)) {  // else begun on the receiving thread
        if (kill_at_s_ && t_k >= *kill_at_s_ - 1e-9) freeze_for_kill(t_k);
        if (hang_at_s_ && t_k >= *hang_at_s_ - 1e-9) {
          freeze_for_hang(t_k);
          // A lockstep CCU cannot rejoin the lock step after a stop (the corners went on under the
          // other CCU; the blocks it missed are gone): it leaves the run.
          std::cout << "bbw_ccu (" << options_.role << "): resumed after a hang in lockstep: leaves the run at " << t_k
                    << " s" << std::endl;
          retired = true;
          break;
        }
        for (const auto& [step, slot] : restarts_) {
          if (step != k) continue;
          for (std::size_t i = 0; i < node_.channels(); ++i) {
            if (node_.channel(i).slot == slot && !wait_for_rejoin(i, ++expected_incarnation[slot], error)) return kExitPeerLost;
          }
        }
        if (brake_) brake_->plan(node_);  // from the vehicle's and pedal's readings of period k - 1
        send_commands(k, false);
      }
      const double t_end = node_.period_end_s(k);
      // Wait until every corner's block k has arrived, or its writer is gone (a dead process).
      // A command is re-sent every 200 ms without progress: a corner that has just (re)joined
      // may have matched our writer only after it was sent.
      auto pred = [&] {
        drain_blocks(t_end, k);
        drain_vehicle();
        drain_health();
        drain_qos_events(t_end, true);
        return fell_out_ || node_.period_complete(k);
      };
      const runtime::PeriodStart begun = clock->begin(k, pred, [&] {
        // No wall-time judgement in lockstep: a silence is not taken for a cut (a loaded machine
        // silences the corners just as well: under six busy loops a standby took 32-60 silences
        // of 50 ms for cuts in 2 of 3 runs and handed the corners to a primary still catching
        // up). Both CCUs' grants are the same, so who leads changes no log; a CCU whose link
        // returns catches up from the repaired blocks, or leaves the run if blocks are gone.
        send_commands(k, false, false);
      });
      if (fell_out_) {
        std::cout << "bbw_ccu (" << options_.role << "): " << fell_out_why_ << ": it cannot rejoin the lock step and leaves the run at "
                  << t_k << " s" << std::endl;
        failover_.demote_reason = "left the lock step";
        retired = true;
        break;
      }
      const bool ok = begun == runtime::PeriodStart::Go;
      if (const std::string failed = node_.end_lockstep_period(k, t_end); !failed.empty()) {
        error = "corner " + failed + " reported failure at period " + std::to_string(k);
        rc = kExitPeerLost;
        break;
      }
      if (!ok) {
        if (events_.interrupted()) break;
        error = "no block for period " + std::to_string(k) + " within " + std::to_string(options_.peer_timeout.count()) +
                " ms from " + node_.lagging(k);
        rc = kExitPeerLost;
        break;
      }
      node_.after_period(t_end);
      periods_done_ = k + 1;
    }
  } else {
    // Realtime: the CCU's clock. Every period it takes what has arrived, checks deadlines and
    // sends every corner its command for the next period; QoS events are handled as they come.
    send_commands(0, false);
    for (std::uint64_t k = 1; k <= periods_ && !events_.interrupted(); ++k) {
      const runtime::PeriodStart begun = clock->begin(k, [&] {
        drain_blocks(0.0);
        drain_health();
        drain_qos_events(0.0, false);
        return false;
      });
      if (begun == runtime::PeriodStart::Interrupted) break;
      const double t_k = static_cast<double>(k) * scenario_.ccu_period_s;
      node_.after_period(realtime_now_s());
      periods_done_ = k;
      if (k == periods_) break;
      if (kill_at_s_ && t_k >= *kill_at_s_ - 1e-9) freeze_for_kill(t_k);
      if (hang_at_s_ && t_k >= *hang_at_s_ - 1e-9) {
        freeze_for_hang(t_k);
        // Resumed: go on from the period the wall clock is in (the missed ones are gone).
        k = std::max(k, static_cast<std::uint64_t>(realtime_now_s() / T));
        if (k >= periods_) break;
        last_send_ = {};
        last_block_at_ = Clock::now();
        continue;
      }
      if (options_.standby) {
        // Out of the loop long enough for the corners to drop this CCU as their owner: stalled
        // (its own commands too far apart: counted), or cut off (no block from any corner: an
        // outage, docs/faults.md "Who commands").
        const auto now = Clock::now();
        const double send_gap_s = std::chrono::duration<double>(now - last_send_).count();
        const double quiet_s = std::chrono::duration<double>(now - last_block_at_).count();
        // A stall beyond the corners' command deadline is counted, not acted on: the corners go
        // to the other CCU for the stall and come back (the commands are the same; docs/faults.md).
        if (last_send_ != Clock::time_point{} && send_gap_s > kOwnershipDeadline_s) {
          ++failover_.stalls;
          last_stall_at_ = now;
          if (failover_.stall_intervals.size() < runtime::CcuFailoverStats::kMaxStallIntervals) {
            const double now_mono_s = runtime::mono_now_s();
            failover_.stall_intervals.push_back({now_mono_s - send_gap_s, now_mono_s});
          }
        }
        // Cut off: no block for kCutOff_s while this CCU itself ran on time (a stall of the whole
        // machine silences the corners too, and is no cut).
        const bool ran_on_time = std::chrono::duration<double>(now - last_stall_at_).count() > kCutOff_s;
        if (last_block_at_ != Clock::time_point{} && quiet_s > kCutOff_s && ran_on_time && k + 4 < periods_ && !cut_off_) {
          demote(t_k, "cut off from every corner");
          cut_off_ = true;  // one outage until a block arrives again
          discard_unsent_commands();
        }
        // The gap to the next send starts now: the demotion's own time (set_qos) is not a stall.
        last_send_ = Clock::now();
      }
      send_commands(k, false);
    }
    // The last blocks: wait for every corner that is still linked to finish (it ends the wait at
    // once when they have). A corner paces itself on its own clock and may end later than this
    // CCU on a loaded machine: with 500 ms a run at load average 10-20 ended with up to 95 of a
    // corner's last samples unreceived (SystemHostileInput.MalformedMeasurements...).
    events_.wait_for(std::chrono::milliseconds(2000), [&] {
      drain_blocks(0.0);
      drain_qos_events(0.0, false);
      return node_.all_linked_finished();
    });
    node_.record_detections();
  }
  wall_s_ = std::chrono::duration<double>(Clock::now() - t0_).count();
  sim_s_ = static_cast<double>(periods_done_) * T;
  write_failover_stats();
  if (stash_overflows_ > 0) {
    std::cerr << "bbw_ccu (" << options_.role << "): " << stash_overflows_
              << " blocks lost: this CCU fell more than 1024 periods behind the corners" << std::endl;
  }
  if (retired) {
    if (log_ != nullptr) log_->flush();
    linger_until_corners_done();
    return rc;
  }
  send_commands(periods_, true);
  for (auto& c : commands_) c->get().get().wait_for_acknowledgments(eprosima::fastrtps::Duration_t(1, 0));
  if (log_ != nullptr) log_->flush();
  return rc;
}

bool CcuApp::lockstep_period_complete(std::uint64_t k) {
  const double t_end = node_.period_end_s(k);
  drain_blocks(t_end, k);
  drain_vehicle();
  drain_health();
  drain_qos_events(t_end, true);
  if (!node_.period_complete(k)) return false;
  if (const std::string failed = node_.end_lockstep_period(k, t_end); !failed.empty()) {
    receive_failure_ = "corner " + failed + " reported failure at period " + std::to_string(k);
    return true;
  }
  node_.after_period(t_end);
  periods_done_ = k + 1;
  return true;
}

bool CcuApp::advance_on_receive() {
  while (lockstep_period_complete(next_k_)) {
    ++progress_;
    next_begun_ = false;
    if (!receive_failure_.empty()) return true;
    ++next_k_;
    if (next_k_ >= periods_ || events_.interrupted()) return true;  // run()'s loop begins what is left
    if (brake_) brake_->plan(node_);  // from the vehicle's and pedal's readings of period k - 1
    send_commands(next_k_, false);
    next_begun_ = true;
  }
  return false;  // waits for more blocks
}

void CcuApp::write_stats(const std::string& file) const {
  runtime::CcuRunStats s;
  s.mode = options_.mode == ClockMode::Lockstep ? "lockstep" : "realtime";
  s.periods_planned = periods_;
  s.periods_done = periods_done_;
  s.sim_s = sim_s_;
  s.wall_s = wall_s_;
  s.killed_at_s = kill_at_s_ ? sim_s_ : -1.0;
  for (const auto& r : blocks_) {
    s.measurement_deadlines_missed += r->get().deadlines_missed();
    s.measurement_liveliness_lost += r->get().liveliness_lost();
    s.measurement_samples_lost += r->get().samples_lost();
    s.qos_events_dropped += r->get().events_dropped();
  }
  for (std::size_t i = 0; i < node_.channels(); ++i) {
    s.foreign_corner_samples += node_.channel(i).foreign_blocks + node_.channel(i).foreign_health;
  }
  s.unknown_corner_blocks = node_.unknown_corner_blocks();
  s.foreign_run_samples = node_.foreign_run_samples();
  s.foreign_runs = dds::join_peer_tags(participant_.foreign_runs());
  for (const auto& c : commands_) s.command_write_failures += c->get().write_failures();
  for (std::size_t i = 0; i < node_.channels(); ++i) {
    const node::CornerChannel& ch = node_.channel(i);
    const faults::CornerSupervisor& sup = node_.core().supervisor(ch.slot);
    const auto& st = sup.calibrator().stats();
    runtime::CcuCornerStats c;
    c.corner = std::string(corner_name(ch.corner));
    c.blocks_received = ch.blocks_received;
    c.samples_received = ch.samples_received;
    c.samples_invalid = ch.samples_invalid;
    c.foreign_blocks = ch.foreign_blocks;
    c.foreign_health = ch.foreign_health;
    c.blocks_over_rate = ch.blocks_over_rate;
    c.block_gaps = ch.block_gaps;
    c.sample_gaps = ch.sample_gaps;
    c.rejoins = ch.rejoins;
    c.deadlines_missed = ch.deadlines_missed;
    c.liveliness_lost = ch.liveliness_lost;
    c.guard_rejected = sup.guard().rejected();
    c.load_cell_ignored = sup.guard().load_cell_ignored();
    c.calibrator_restarts = sup.calibrator_restarts();
    c.fits_accepted = st.fits_accepted;
    c.fits_rejected = st.fits_rejected;
    c.cycles_detected = st.cycles_detected;
    c.samples_rejected = st.samples_rejected;
    c.first_fit_time_s = st.first_fit_time_s;
    c.calibration_version = ch.calibration_version;
    const auto& curve = sup.calibrator().curve();
    c.curve_a = curve.a;
    c.curve_b = curve.b;
    c.curve_c = curve.c;
    c.curve_d = curve.d;
    s.corners.push_back(c);
  }
  // Every detection in time order of recording: corner, finding, onset, detection time.
  for (const node::DetectionRecord& d : node_.detections()) {
    s.detections.push_back({std::string(corner_name(static_cast<Corner>(d.slot))), std::string(faults::to_string(d.finding)),
                            std::string(faults::to_string(faults::part_of(d.finding))), d.onset_s, d.detected_s});
  }
  runtime::save(s, file);
}

}  // namespace bbw::ccu
