#include "bbw/node/in_process.hpp"

#include <stdexcept>
#include <string>

namespace bbw::node {

InProcessRun::InProcessRun(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
                           const InProcessOptions& options)
    : scenario_(scenario), ccu_(scenario, calibrator, options.friction_feedback) {
  if (!faults::process_actions(options.schedule).empty()) {
    throw std::invalid_argument(scenario.file + ": process faults (kill, restart) need real processes; run it with ./bbw run");
  }
  command_out_ = commands_.sender(next_endpoint_++);
  calibration_out_ = calibration_.sender(next_endpoint_++);
  corners_.resize(ccu_.channels());
  for (std::size_t i = 0; i < ccu_.channels(); ++i) {
    CornerEnd& c = corners_[i];
    CornerNodeOptions o;
    o.corner = ccu_.channel(i).corner;
    o.scenario_index = i;  // the CCU's channels are in scenario order
    o.lockstep = true;
    o.schedule = options.schedule;
    o.watchdog = options.watchdog;
    c.node = std::make_unique<CornerNode>(scenario, o);
    const std::string name = corner_name(o.corner);
    c.blocks = std::make_unique<transport::InMemoryTopic<msg::MeasurementBlock>>("MeasurementBlock/corner_" + name);
    c.health = std::make_unique<transport::InMemoryTopic<msg::CornerHealth>>("CornerHealth/corner_" + name);
    c.block_in = c.blocks->receiver();
    c.health_in = c.health->receiver();
    c.block_out = c.blocks->sender(next_endpoint_++);
    c.health_out = c.health->sender(next_endpoint_++);
    c.command_in = commands_.receiver();
    c.calibration_in = calibration_.receiver();
  }
  // Start-up as over DDS: every corner announces itself, the CCU sends the initial models.
  for (CornerEnd& c : corners_) c.health_out->send(c.node->health(msg::HEALTH_STARTING));
  for (const msg::CalibrationState& s : ccu_.initial_states()) calibration_out_->send(s);
}

InProcessRun::~InProcessRun() { ccu_.set_observer(nullptr); }

void InProcessRun::corner_period(CornerEnd& c, std::uint64_t k) {
  if (c.stopped) return;
  // drain_inputs: commands, then calibration states.
  while (c.command_in->take(command_)) c.node->on_command(command_, 0.0);
  while (c.calibration_in->take(state_)) c.node->on_calibration(state_);
  if (!c.started) {
    if (!c.node->have_command()) return;
    c.node->start();
    c.health_out->send(c.node->health(msg::HEALTH_RUNNING));
    c.started = true;
  }
  if (!c.node->granted(k)) return;
  if (c.node->latest_command().stop()) {
    c.stopped = true;
    return;
  }
  if (const msg::MeasurementBlock* b = c.node->simulate_period(k)) c.node->block_sent(c.block_out->send(*b));
}

void InProcessRun::ccu_intake(double t_end_s) {
  transport::EndpointId from = 0;
  for (std::size_t i = 0; i < corners_.size(); ++i) {
    while (corners_[i].block_in->take(block_, from)) {
      ccu_.on_block(i, block_, from, t_end_s);
      for (const msg::CalibrationState* s : ccu_.calibration_updates()) calibration_out_->send(*s);
      ccu_.clear_calibration_updates();
    }
    while (corners_[i].health_in->take(health_)) ccu_.on_health(i, health_);
  }
}

bool InProcessRun::step() {
  const std::uint64_t k = next_;
  if (k >= ccu_.periods()) return false;
  const double t_end = ccu_.period_end_s(k);
  if (k == 0) ccu_intake(0.0);  // the corners' start-up health
  for (const msg::ClampCommand& c : ccu_.commands(k, false)) command_out_->send(c);
  for (CornerEnd& c : corners_) corner_period(c, k);
  ccu_intake(t_end);
  if (!ccu_.period_complete(k)) {
    throw std::logic_error("in-process lockstep: period " + std::to_string(k) + " incomplete (" + ccu_.lagging(k) + ")");
  }
  if (const std::string failed = ccu_.end_lockstep_period(k, t_end); !failed.empty()) {
    throw std::runtime_error("corner " + failed + " reported failure at period " + std::to_string(k));
  }
  ccu_.after_period(t_end);
  next_ = k + 1;
  if (next_ == ccu_.periods()) {
    for (const msg::ClampCommand& c : ccu_.commands(next_, true)) command_out_->send(c);
    for (CornerEnd& c : corners_) corner_period(c, next_);
  }
  return true;
}

}  // namespace bbw::node
