#include "bbw/node/in_process.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace bbw::node {

namespace {

// Who sent a command on the in-memory bus: its run id, the sending endpoint's id as the writer,
// and whether that endpoint is the CCU's command outlet (the bus knows; over DDS the participant's
// announcement says it).
corner::CommandSource command_source(const msg::ClampCommand& c, transport::EndpointId from, transport::EndpointId ccu) {
  corner::CommandSource s{c.run_id(), {}, from == ccu};
  for (std::size_t i = 0; i < 8; ++i) s.writer[i] = static_cast<std::uint8_t>(from >> (8 * i));
  return s;
}

}  // namespace

namespace {

faults::Target target_of(Corner c) { return static_cast<faults::Target>(corner_index(c)); }

}  // namespace

InProcessRun::InProcessRun(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
                           const InProcessOptions& options)
    : scenario_(scenario),
      options_(options),
      ccu_(scenario, calibrator, options.friction_feedback, options.monitor, options.reactions) {
  if (options.schedule.standby) {
    throw std::invalid_argument(scenario.file + ": a hot-standby CCU (standby: true) runs only over DDS (./bbw run): "
                                "it rests on DDS exclusive ownership");
  }
  const auto actions = faults::process_actions(options.schedule);
  if (!actions.empty() && !options.process_faults) {
    throw std::invalid_argument(scenario.file + ": process faults (kill, restart) are carried out only with "
                                "InProcessOptions::process_faults (or run it with ./bbw run)");
  }
  for (const faults::ProcessAction& a : actions) {
    if (a.target != faults::Target::CCU) continue;
    if (a.kind == faults::ProcessAction::Kind::Restart) {
      throw std::invalid_argument(scenario.file + ": restarting the CCU is not supported (a kill of the CCU ends its part in the run)");
    }
    if (!ccu_kill_at_s_) ccu_kill_at_s_ = a.at_s;
  }
  ccu_command_endpoint_ = next_endpoint_;
  command_out_ = commands_.sender(next_endpoint_++);
  ccu_.set_run_id(options.run_id);
  calibration_out_ = calibration_.sender(next_endpoint_++);
  corners_.resize(ccu_.channels());
  for (std::size_t i = 0; i < ccu_.channels(); ++i) {
    CornerEnd& c = corners_[i];
    CornerNodeOptions o;
    o.corner = ccu_.channel(i).corner;
    o.scenario_index = i;  // the CCU's channels are in scenario order
    o.lockstep = true;
    o.run_id = options_.run_id;
    o.schedule = options.schedule;
    o.watchdog = options.watchdog;
    c.node = std::make_unique<CornerNode>(scenario, o);
    const std::string name = corner_name(o.corner);
    c.blocks = std::make_unique<transport::InMemoryTopic<msg::MeasurementBlock>>("MeasurementBlock/corner_" + name);
    c.health = std::make_unique<transport::InMemoryTopic<msg::CornerHealth>>("CornerHealth/corner_" + name);
    c.block_in = c.blocks->receiver();
    c.health_in = c.health->receiver();
    connect_corner(c);
  }
  // Start-up as over DDS: every corner announces itself, the CCU sends the initial models.
  for (CornerEnd& c : corners_) c.health_out->send(c.node->health(msg::HEALTH_STARTING));
  for (const msg::CalibrationState& s : ccu_.initial_states()) send_calibration(s);
}

InProcessRun::~InProcessRun() { ccu_.set_observer(nullptr); }

// A corner process's endpoints: its writers are new endpoints, its readers new subscriptions.
void InProcessRun::connect_corner(CornerEnd& c) {
  c.block_writer = next_endpoint_++;
  c.block_out = c.blocks->sender(c.block_writer);
  c.health_out = c.health->sender(next_endpoint_++);
  c.command_in = commands_.receiver();
  c.calibration_in = calibration_.receiver();
}

void InProcessRun::set_corner_observer(std::size_t i, CornerObserver* observer) {
  corners_[i].observer = observer;
  corners_[i].node->set_observer(observer);
}

void InProcessRun::send_calibration(const msg::CalibrationState& s) {
  calibration_out_->send(s);
  if (!options_.process_faults) return;
  // Kept for a late joiner (a restarted corner), as the TRANSIENT_LOCAL state writer does.
  for (std::size_t i = 0; i < corners_.size(); ++i) {
    if (ccu_.channel(i).slot == s.corner_id()) corners_[i].last_state = s;
  }
}

// The scheduled kill: the process stops dead (its counters stay with the retired node); the CCU
// finds its writer gone at this period's end. A restart scheduled after it starts the next
// incarnation at once (the launcher does not wait in lockstep); it joins at the restart time.
void InProcessRun::kill_corner(CornerEnd& c, std::size_t i) {
  const double now_s = c.node->time_s();
  c.lost_writer = c.block_writer;
  c.restart_at_s.reset();
  for (const faults::ProcessAction& a : faults::process_actions(options_.schedule)) {
    if (a.kind == faults::ProcessAction::Kind::Restart && a.target == target_of(c.node->corner()) && a.at_s > now_s) {
      c.restart_at_s = a.at_s;
      break;
    }
  }
  c.node->finish(0, 0);
  c.dead = true;
  c.started = false;
  c.command_in.reset();
  c.calibration_in.reset();
  if (!c.restart_at_s) return;  // the dead node stays the corner's last incarnation
  CornerNodeOptions o;
  o.corner = c.node->corner();
  o.scenario_index = i;
  o.lockstep = true;
  o.run_id = options_.run_id;
  o.schedule = options_.schedule;
  o.watchdog = options_.watchdog;
  o.incarnation = c.node->incarnation() + 1;
  retired_.push_back(std::move(c.node));
  o.resume_at_s = *c.restart_at_s;
  c.node = std::make_unique<CornerNode>(scenario_, o);
  c.node->set_observer(c.observer);
  connect_corner(c);
  c.dead = false;
  c.expected_incarnation = o.incarnation;
  c.rejoin_step = c.node->resume_step();
  if (c.last_state) c.node->on_calibration(*c.last_state);
  c.health_out->send(c.node->health(msg::HEALTH_STARTING));
}

void InProcessRun::corner_period(CornerEnd& c, std::uint64_t k) {
  if (c.stopped || c.dead) return;
  // drain_inputs: commands, then calibration states.
  transport::EndpointId from = 0;
  while (c.command_in->take(command_, from)) c.node->on_command(command_, command_source(command_, from, ccu_command_endpoint_), 0.0);
  while (c.calibration_in->take(state_)) c.node->on_calibration(state_);
  if (!c.started) {
    if (!c.node->have_command()) return;
    c.node->start();
    c.health_out->send(c.node->health(msg::HEALTH_RUNNING));
    c.started = true;
  }
  if (options_.process_faults && k < c.node->periods() && c.node->kill_due()) {
    kill_corner(c, static_cast<std::size_t>(&c - corners_.data()));
    return;
  }
  if (!c.node->ccu_lost()) {
    if (!ccu_alive_) {
      // Waiting for the grant of period k, the corner finds the CCU's command writer gone.
      if (!c.node->granted(k)) c.node->set_ccu_lost();
    }
    if (!c.node->ccu_lost()) {
      if (!c.node->granted(k)) return;
      if (c.node->latest_command().stop()) {
        c.stopped = true;
        return;
      }
    }
  }
  if (const msg::MeasurementBlock* b = c.node->simulate_period(k)) c.node->block_sent(c.block_out->send(*b));
}

void InProcessRun::ccu_intake(double t_end_s) {
  transport::EndpointId from = 0;
  for (std::size_t i = 0; i < corners_.size(); ++i) {
    while (corners_[i].block_in->take(block_, from)) {
      if (tap_) tap_(i, block_);
      ccu_.on_block(i, block_, from, t_end_s);
      for (const msg::CalibrationState* s : ccu_.calibration_updates()) send_calibration(*s);
      ccu_.clear_calibration_updates();
    }
    while (corners_[i].health_in->take(health_)) ccu_.on_health(i, health_);
  }
}

bool InProcessRun::step() {
  const std::uint64_t k = next_;
  if (k >= ccu_.periods()) return false;
  const double t_end = ccu_.period_end_s(k);
  if (ccu_alive_ && ccu_kill_at_s_ && ccu_.period_start_s(k) >= *ccu_kill_at_s_ - 1e-9) {
    ccu_alive_ = false;  // from here on the CCU sends and reads nothing
  }
  if (ccu_alive_) {
    if (k == 0) ccu_intake(0.0);  // the corners' start-up health
    for (std::size_t i = 0; i < corners_.size(); ++i) {
      CornerEnd& c = corners_[i];
      if (!c.rejoin_step || *c.rejoin_step != k) continue;
      // The CCU holds the clock for the restarted corner until it has announced itself.
      const CornerChannel& ch = ccu_.channel(i);
      if (ch.health_incarnation < c.expected_incarnation ||
          (ch.health != msg::HEALTH_STARTING && ch.health != msg::HEALTH_RUNNING)) {
        throw std::logic_error(std::string("in-process: restarted corner ") + corner_name(ch.corner) +
                               " has not announced itself by period " + std::to_string(k));
      }
      ccu_.expect_rejoin(i);
      c.rejoin_step.reset();
    }
    for (const msg::ClampCommand& c : ccu_.commands(k, false)) command_out_->send(c);
  }
  for (CornerEnd& c : corners_) corner_period(c, k);
  if (period_hook_) period_hook_(k);
  if (ccu_alive_) {
    ccu_intake(t_end);
    for (std::size_t i = 0; i < corners_.size(); ++i) {
      CornerEnd& c = corners_[i];
      if (!c.lost_writer) continue;
      ccu_.on_writer_lost(i, *c.lost_writer, t_end, true, CcuNode::WriterLoss::Left);
      c.lost_writer.reset();
    }
    if (!ccu_.period_complete(k)) {
      throw std::logic_error("in-process lockstep: period " + std::to_string(k) + " incomplete (" + ccu_.lagging(k) + ")");
    }
    if (const std::string failed = ccu_.end_lockstep_period(k, t_end); !failed.empty()) {
      throw std::runtime_error("corner " + failed + " reported failure at period " + std::to_string(k));
    }
    ccu_.after_period(t_end);
  } else {
    // Nobody reads what the corners still send.
    for (CornerEnd& c : corners_) {
      while (c.block_in->take(block_)) {
      }
      while (c.health_in->take(health_)) {
      }
      c.lost_writer.reset();
    }
  }
  next_ = k + 1;
  if (next_ == ccu_.periods() && ccu_alive_) {
    for (const msg::ClampCommand& c : ccu_.commands(next_, true)) command_out_->send(c);
    for (CornerEnd& c : corners_) corner_period(c, next_);
  }
  return true;
}

}  // namespace bbw::node
