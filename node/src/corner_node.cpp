#include "bbw/node/corner_node.hpp"

#include <algorithm>

#include <cmath>
#include <stdexcept>
#include <string>

namespace bbw::node {

std::uint64_t steps_per_period(const scenario::Scenario& s) {
  const double ratio = s.ccu_period_s / s.plant_dt_s;
  const double rounded = std::round(ratio);
  if (std::fabs(ratio - rounded) > 1e-9 || rounded < 1.0 || rounded > msg::MAX_BLOCK_SAMPLES) {
    throw std::invalid_argument(s.file + ": ccu_period_s / plant_dt_s must be an integer in [1, " +
                                std::to_string(msg::MAX_BLOCK_SAMPLES) + "], got " + std::to_string(ratio));
  }
  return static_cast<std::uint64_t>(rounded);
}

std::uint64_t periods_of(const scenario::Scenario& s) {
  return static_cast<std::uint64_t>(std::ceil(s.duration_s / s.ccu_period_s - 1e-9));
}

namespace {

const scenario::Scenario& validated(const scenario::Scenario& s, const CornerNodeOptions& o) {
  if (o.scenario_index >= s.corners.size()) throw std::invalid_argument("corner index out of range");
  if (s.corners[o.scenario_index].name != corner_name(o.corner)) {
    throw std::invalid_argument("scenario corner " + std::to_string(o.scenario_index) + " is '" +
                                s.corners[o.scenario_index].name + "', not " + corner_name(o.corner));
  }
  steps_per_period(s);
  if (!(o.resume_at_s >= 0.0 && o.resume_at_s < s.duration_s)) {
    throw std::invalid_argument("resume time " + std::to_string(o.resume_at_s) + " s is outside the scenario (0 to " +
                                std::to_string(s.duration_s) + " s)");
  }
  return s;
}

faults::Target target_of(Corner c) { return static_cast<faults::Target>(corner_index(c)); }

// The caliper's rated clamp force from the plant config; the rate allows the full range in one
// CCU period.
corner::CommandGateParams gate_params(const scenario::Scenario& s, bool standby) {
  corner::CommandGateParams p;
  p.max_sources = standby ? 2 : 1;
  p.max_force_kN = s.plant.rated_clamp_force_kN;
  p.max_rate_kN_per_s = p.max_force_kN / s.ccu_period_s;
  return p;
}

}  // namespace

CornerNode::CornerNode(const scenario::Scenario& scenario, const CornerNodeOptions& options)
    : scenario_(validated(scenario, options)),
      options_(options),
      sim_(scenario, options.scenario_index),
      steps_per_period_(steps_per_period(scenario)),
      periods_(periods_of(scenario)),
      my_id_(static_cast<std::uint8_t>(corner_index(options.corner))),
      gate_(options.run_id, gate_params(scenario, options.standby)),
      injector_(options.schedule, target_of(options.corner),
                scenario::corner_seed(scenario.seed + 7777, options.scenario_index)),
      link_(options.schedule, target_of(options.corner)),
      watchdog_(options.watchdog),
      resume_step_(static_cast<std::uint64_t>(std::ceil(options.resume_at_s / scenario.ccu_period_s - 1e-9))) {
  for (const faults::ProcessAction& a : faults::process_actions(options.schedule)) {
    // The CCU freezes at the first period start at or after its kill (ccu_app.cpp).
    if (a.target == faults::Target::CCU && a.kind == faults::ProcessAction::Kind::Kill && !ccu_kill_at_s_) {
      ccu_kill_at_s_ = std::ceil(a.at_s / scenario.ccu_period_s - 1e-9) * scenario.ccu_period_s;
    }
  }
  block_.corner_id(my_id_);
  block_.run_id(options.run_id);
  block_.incarnation(options.incarnation);
  block_.samples().reserve(msg::MAX_BLOCK_SAMPLES);
  for (dds::CalibrationModel* m : {&model_, &candidate_}) {
    m->friction.delta_rev.reserve(msg::MAX_FRICTION_ELEMENTS);
    m->friction.stiffness_kN_per_rev.reserve(msg::MAX_FRICTION_ELEMENTS);
  }
}

msg::CornerHealth CornerNode::health(std::uint8_t status) const {
  msg::CornerHealth h;
  h.corner_id(my_id_);
  h.run_id(options_.run_id);
  h.status(status);
  h.samples_published(stats_.samples_published);
  h.blocks_published(stats_.blocks_published);
  h.commands_received(stats_.commands_received);
  h.commands_applied(stats_.commands_applied);
  h.command_seq_gaps(stats_.command_seq_gaps);
  h.overruns(stats_.overruns);
  h.max_jitter_s(stats_.max_jitter_s);
  h.time_s(sim_.time_s());
  h.incarnation(options_.incarnation);
  h.resume_step(resume_step_);
  return h;
}

void CornerNode::on_command(const msg::ClampCommand& cmd, const corner::CommandSource& source, double arrival_s) {
  if (cmd.corner_id() != my_id_) return;  // another corner's command (no content filter on the topic)
  // The command gate (issue 17): this run's, from the CCU matched at start, force within the
  // caliper's rated range and rate; a refused command is counted and never read further.
  const corner::GateResult gated = gate_.check(source, cmd.mode() == msg::MODE_FORCE, cmd.clamp_force_kN(), cmd.time_s());
  if (!gated.applies()) return;
  const double force_kN = cmd.mode() == msg::MODE_FORCE ? gated.force_kN : cmd.clamp_force_kN();
  ++stats_.commands_received;
  // A run with a hot-standby CCU: each CCU numbers its own commands, so the numbering starts
  // again at a change of writer (DDS exclusive ownership changed hands).
  const bool new_writer = options_.standby && have_command_ && source.writer != last_writer_;
  if (new_writer) last_command_seq_.reset();
  last_writer_ = source.writer;
  if (last_command_seq_ && cmd.seq() != *last_command_seq_ + 1) {
    stats_.command_seq_gaps += cmd.seq() > *last_command_seq_ ? cmd.seq() - *last_command_seq_ - 1 : 1;
  }
  last_command_seq_ = cmd.seq();
  if (cmd.step() < resume_step_ && !cmd.stop()) return;  // a restarted corner joins at its resume step
  // Realtime: a takeover's command may name an earlier period (the two CCUs' clocks start apart);
  // it is taken all the same (DDS ownership chose its writer). A stale one (a returning CCU's
  // last command, delivered again by reliability) never gets here: the adapter drops commands
  // written too long ago (CornerApp::drain_inputs).
  const bool takeover = new_writer && !options_.lockstep;
  if (!have_command_ || cmd.step() >= latest_command_.step() || takeover) {
    ++stats_.commands_taken;
    latest_command_ = cmd;
    latest_command_.clamp_force_kN(force_kN);
    have_command_ = true;
    if (cmd.valid() && (cmd.mode() == msg::MODE_FORCE || cmd.mode() == msg::MODE_RELEASE)) {
      // Lockstep (and the start command): the command belongs to its period's start.
      // Realtime: to its arrival on this corner's clock.
      const double at = options_.lockstep || !started_ ? cmd.time_s() : arrival_s;
      watchdog_.on_command(at, cmd.mode() == msg::MODE_FORCE ? force_kN : 0.0);
    }
  }
}

void CornerNode::on_calibration(const msg::CalibrationState& state) {
  if (state.corner_id() != my_id_) return;
  if (state.run_id() != options_.run_id) {
    ++stats_.calibrations_rejected;  // another run's
    return;
  }
  calibration_seen_ = std::max(calibration_seen_, static_cast<std::uint64_t>(state.version()));
  if (state.version() < model_.version && friction_.started()) return;  // stale
  // Decoded into a spare model sized at construction, then swapped in: no allocation per model.
  if (!dds::from_msg(state, candidate_)) {
    ++stats_.calibrations_rejected;
    return;
  }
  if (!model_.friction.delta_rev.empty() && candidate_.friction.delta_rev != model_.friction.delta_rev) {
    ++stats_.calibrations_rejected;  // thresholds are fixed by the calibrator config
    return;
  }
  std::swap(model_, candidate_);
  ++stats_.calibrations_applied;
}

std::uint64_t CornerNode::start() {
  const std::uint64_t first = std::max(resume_step_, latest_command_.step());
  resume_step_ = first;
  if (first > 0) sim_.start_at(static_cast<double>(first) * scenario_.ccu_period_s);
  started_ = true;
  return first;
}

bool CornerNode::kill_due() const { return link_.killed(sim_.time_s() + scenario_.plant_dt_s); }

bool CornerNode::alone() const {
  const auto mode = watchdog_.at(sim_.time_s()).mode;
  return ccu_lost_ || mode == faults::WatchdogMode::Holding || mode == faults::WatchdogMode::Default;
}

const msg::MeasurementBlock* CornerNode::simulate_period(std::uint64_t k) {
  const double dt = scenario_.plant_dt_s;
  scenario::ExternalInputs ext;
  ext.temperature_C = caliper_temperature_C_;
  const bool valid = have_command_ && latest_command_.valid();
  if (valid && !ccu_lost_) ++stats_.commands_applied;
  const bool calibrated = model_.version > 0 && latest_command_.use_friction_comp();
  if (calibrated) ext.curve = model_.curve;
  // A CCU fault reaction: the feedback to use instead of the corner's own.
  if (have_command_ && latest_command_.feedback_override() == msg::FEEDBACK_CURVE) {
    ext.feedback = corner_unit::ForceFeedback::Curve;
    ext.curve = scenario::CurveEstimate{latest_command_.override_curve_a_kN_per_rev3(),
                                        latest_command_.override_curve_b_kN_per_rev2(),
                                        latest_command_.override_curve_c_kN_per_rev(),
                                        latest_command_.override_curve_d_kN()};
  } else if (have_command_ && latest_command_.feedback_override() == msg::FEEDBACK_LOAD_CELL) {
    ext.feedback = corner_unit::ForceFeedback::LoadCell;
  }

  block_.block_seq(k);
  block_.period_start_s(sim_.time_s());
  block_.samples().clear();
  faults::WatchdogOutput w;
  msg::MeasurementSample& m = sample_;  // reused: a message's default constructor re-registers its TypeObject
  for (std::uint64_t i = 0; i < steps_per_period_; ++i) {
    const double t_end = sim_.time_s() + dt;
    // Force mode: the CCU's command through the watchdog (hold, then the default, if it is lost).
    w = watchdog_.at(t_end);
    if (w.force_command_kN) ext.force_command_kN = w.force_command_kN;
    if (w.mode == faults::WatchdogMode::Holding && stats_.ccu_lost_s < 0.0) stats_.ccu_lost_s = t_end;
    if (w.mode == faults::WatchdogMode::Default && stats_.default_force_s < 0.0) stats_.default_force_s = t_end;
    // Friction the load cell is believed to hold, from the CCU's model (Maxwell-slip elements
    // and the calibrator's optional effect terms) and this corner's own element and play states
    // (they depend only on the position history).
    const double x = sim_.last().position_rev;
    double friction = 0.0;
    if (!model_.friction.delta_rev.empty()) {
      if (!friction_.started()) friction_.reset(model_.friction.delta_rev.size(), x);
      friction = friction_.step_load_cell_excess(model_.friction, x, sim_.last().speed_rev_per_s, sim_.last().temperature_C);
    }
    ext.friction_estimate_kN = calibrated ? friction : 0.0;
    injector_.prepare(ext, t_end);
    const auto& s = sim_.step(dt, ext);
    dds::to_msg(s, calibrated && sim_.feedback() == corner_unit::ForceFeedback::Compensated, m);
    // Network faults on the way out: silence drops the sample, a delay holds it back (order kept).
    if (link_.silenced(s.time_s)) {
      ++stats_.samples_suppressed;
    } else if (const double d = link_.delay_s(s.time_s); d > 0.0 || outbox_.size() > 0) {
      if (d > 0.0) ++stats_.samples_delayed;
      if (!outbox_.push(s.time_s + d, m)) ++stats_.samples_suppressed;
    } else if (block_.samples().size() < msg::MAX_BLOCK_SAMPLES) {
      block_.samples().push_back(m);
    }
  }
  while (block_.samples().size() < msg::MAX_BLOCK_SAMPLES) {
    auto due = outbox_.pop_due(sim_.time_s() + 1e-9);
    if (!due) break;
    block_.samples().push_back(*due);
  }
  block_.first_sample_seq(block_.samples().empty() ? 0 : block_.samples().front().seq());
  last_mode_ = w.mode;
  ++stats_.periods;
  if (observer_ != nullptr) {
    observer_->on_period(PeriodRecord{sim_.time_s(), sim_.last().force_true_kN, ext.force_command_kN, w.mode,
                                      options_.incarnation});
  }
  // Lockstep: an empty block still tells the CCU that this period is done (time is simulated).
  // Realtime: nothing to send is nothing sent.
  if (options_.lockstep || !block_.samples().empty()) return &block_;
  return nullptr;
}

void CornerNode::block_sent(bool ok) {
  if (!ok) {
    ++stats_.write_failures;
    return;
  }
  ++stats_.blocks_published;
  stats_.samples_published += block_.samples().size();
  // Not receivable: samples after the period the scheduled CCU kill froze the CCU at.
  // Not the watchdog's view: a CCU that is only late (a loaded machine, realtime) still receives
  // every sample, and counting those made summary.json's samples_lost negative (issue 14).
  if (ccu_kill_at_s_) {
    for (const auto& m : block_.samples()) {
      if (m.time_s() > *ccu_kill_at_s_ + 1e-9) ++stats_.samples_without_ccu;
    }
  }
}

void CornerNode::finish(std::uint64_t transport_write_failures, std::uint64_t command_deadlines_missed) {
  stats_.command_deadlines_missed = command_deadlines_missed;
  stats_.write_failures += transport_write_failures;
  stats_.samples_in_flight = outbox_.size();
  stats_.first_step = resume_step_;
}

}  // namespace bbw::node
