#include "corner_app.hpp"

#include "bbw/security/dds_security.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "bbw/calibration/maxwell_slip.hpp"
#include "bbw/dds/run_id.hpp"
#include "bbw/dds/topics.hpp"
#include "bbw/launch/stats_file.hpp"

namespace bbw::corner_process {

namespace {

using Clock = std::chrono::steady_clock;

std::uint64_t steps_per_period(const scenario::Scenario& s) {
  const double ratio = s.ccu_period_s / s.plant_dt_s;
  const double rounded = std::round(ratio);
  if (std::fabs(ratio - rounded) > 1e-9 || rounded < 1.0 || rounded > msg::MAX_BLOCK_SAMPLES) {
    throw std::invalid_argument(s.file + ": ccu_period_s / plant_dt_s must be an integer in [1, " +
                                std::to_string(msg::MAX_BLOCK_SAMPLES) + "], got " + std::to_string(ratio));
  }
  return static_cast<std::uint64_t>(rounded);
}

const scenario::Scenario& validated(const scenario::Scenario& s, const CornerOptions& o) {
  if (o.scenario_index >= s.corners.size()) throw std::invalid_argument("corner index out of range");
  if (s.corners[o.scenario_index].name != dds::corner_name(o.corner)) {
    throw std::invalid_argument("scenario corner " + std::to_string(o.scenario_index) + " is '" +
                                s.corners[o.scenario_index].name + "', not " + dds::corner_name(o.corner));
  }
  steps_per_period(s);
  if (!(o.resume_at_s >= 0.0 && o.resume_at_s < s.duration_s)) {
    throw std::invalid_argument("resume time " + std::to_string(o.resume_at_s) + " s is outside the scenario (0 to " +
                                std::to_string(s.duration_s) + " s)");
  }
  return s;
}

dds::ParticipantOptions named(dds::ParticipantOptions p, dds::Corner c) {
  if (p.name.empty()) p.name = std::string("bbw_corner_") + dds::corner_name(c);
  return p;
}

std::string own_partition(const CornerOptions& o) {
  return dds::corner_run_partition(security::corner_partition(static_cast<int>(dds::corner_index(o.corner))),
                                   o.participant.run_id);
}

// The caliper's rated clamp force from the plant config; the rate allows the full range in one
// CCU period.
corner::CommandGateParams gate_params(const scenario::Scenario& s) {
  corner::CommandGateParams p;
  p.max_force_kN = s.plant.rated_clamp_force_kN;
  p.max_rate_kN_per_s = p.max_force_kN / s.ccu_period_s;
  return p;
}

faults::Target target_of(dds::Corner c) { return static_cast<faults::Target>(dds::corner_index(c)); }

}  // namespace

CornerApp::CornerApp(const scenario::Scenario& scenario, const CornerOptions& options, dds::Events& events)
    : scenario_(validated(scenario, options)),
      options_(options),
      events_(events),
      sim_(scenario, options.scenario_index),
      steps_per_period_(steps_per_period(scenario)),
      periods_(static_cast<std::uint64_t>(std::ceil(scenario.duration_s / scenario.ccu_period_s - 1e-9))),
      participant_(named(options.participant, options.corner)),
      // Measurements and health in the corner's own partition of this run (corner_FL.run_<id>,
      // bbw/dds/run_id.hpp), secure or not: the permissions grant a corner only its own
      // (docs/security.md). Commands and calibration state in the run's partition run_<id>.
      blocks_(participant_, dds::kMeasurementTopic,
              dds::profiles_for(options.mode == ClockMode::Lockstep).measurement_writer, events,
              dds::Partition{own_partition(options)}),
      health_(participant_, dds::kHealthTopic, "state_writer", events, dds::Partition{own_partition(options)}),
      // No DDS content filter on these topics: Fast DDS 2.9 evaluates DDS-SQL filters on the
      // writer by deserialising into DynamicData, which throws and catches internally on every
      // sample and made the CCU's command writes its largest cost. Corners drop the other
      // corners' samples here instead (4 commands per period, a few bytes each).
      commands_(participant_, dds::kCommandTopic,
                dds::profiles_for(options.mode == ClockMode::Lockstep).command_reader, events,
                dds::Partition{dds::run_partition(options.participant.run_id)}),
      calibration_(participant_, dds::kCalibrationTopic, "state_reader", events,
                   dds::Partition{dds::run_partition(options.participant.run_id)}),
      gate_(options.participant.run_id, gate_params(scenario)),
      my_id_(static_cast<std::uint8_t>(dds::corner_index(options.corner))),
      injector_(options.schedule, target_of(options.corner),
                scenario::corner_seed(scenario.seed + 7777, options.scenario_index)),
      link_(options.schedule, target_of(options.corner)),
      watchdog_(options.watchdog),
      resume_step_(static_cast<std::uint64_t>(std::ceil(options.resume_at_s / scenario.ccu_period_s - 1e-9))) {
  block_.corner_id(my_id_);
  block_.run_id(options.participant.run_id);
  block_.incarnation(options.incarnation);
  block_.samples().reserve(msg::MAX_BLOCK_SAMPLES);
  if (!options.periods_log.empty()) {
    // A restarted process appends to its predecessor's log.
    periods_csv_ = std::fopen(options.periods_log.c_str(), options.incarnation == 0 ? "w" : "a");
    if (periods_csv_ == nullptr) throw std::runtime_error(options.periods_log + ": cannot write");
    if (options.incarnation == 0) std::fputs("time_s,force_true_kN,applied_kN,watchdog_mode,incarnation\n", periods_csv_);
  }
}

CornerApp::~CornerApp() {
  if (periods_csv_ != nullptr) std::fclose(periods_csv_);
}

void CornerApp::publish_health(std::uint8_t status) {
  msg::CornerHealth h;
  h.corner_id(my_id_);
  h.run_id(participant_.run_id());
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
  health_.write(h);
}

bool CornerApp::wait_for_ccu(std::string& error) {
  const auto timeout = options_.match_timeout.count() > 0 ? options_.match_timeout : options_.discovery_timeout;
  const bool ok = events_.wait_for(timeout, [&] {
    return blocks_.matched() >= 1 && commands_.matched() >= 1 && calibration_.matched() >= 1 &&
           health_.matched() >= 1;
  });
  matched_ccu_ = ok;
  if (!ok && !events_.interrupted()) {
    error = std::string("CCU not discovered within ") +
            std::to_string(timeout.count()) + " ms (measurement readers matched: " +
            std::to_string(blocks_.matched()) + ", command writers matched: " +
            std::to_string(commands_.matched()) + ")";
  }
  return ok;
}

double CornerApp::sim_now_s() const {
  return static_cast<double>(resume_step_) * scenario_.ccu_period_s +
         std::chrono::duration<double>(Clock::now() - t0_).count();
}

bool CornerApp::ccu_gone() const {
  return (commands_.liveliness_lost() > 0 && commands_.alive_writers() == 0) || commands_.matched() == 0;
}

// Takes every waiting command and calibration state; keeps the newest command.
void CornerApp::drain_inputs() {
  msg::ClampCommand cmd;
  eprosima::fastdds::dds::SampleInfo info;
  while (commands_.take(cmd, info)) {
    if (cmd.corner_id() != my_id_) continue;
    // The command gate (issue 17): this run's, from the CCU matched at start (the first writer
    // whose participant announced itself as this run's bbw_ccu), force within the caliper's
    // rated range and rate; a refused command is counted and never read further.
    corner::CommandSource source{cmd.run_id(), {}, false};
    for (std::size_t i = 0; i < source.writer.size(); ++i) source.writer[i] = info.publication_handle.value[i];
    if (!gate_.pinned()) {  // the announcement matters only until the CCU's writer is pinned
      std::array<std::uint8_t, 12> prefix{};
      std::copy_n(source.writer.begin(), prefix.size(), prefix.begin());
      const auto tag = participant_.peer_tag(prefix);
      source.announced_as_ccu = tag && tag->run_id == participant_.run_id() && tag->name == "bbw_ccu";
    }
    const corner::GateResult gated = gate_.check(source, cmd.mode() == msg::MODE_FORCE, cmd.clamp_force_kN(), cmd.time_s());
    if (!gated.applies()) continue;
    if (cmd.mode() == msg::MODE_FORCE) cmd.clamp_force_kN(gated.force_kN);
    ++stats_.commands_received;
    if (last_command_seq_ && cmd.seq() != *last_command_seq_ + 1) {
      stats_.command_seq_gaps += cmd.seq() > *last_command_seq_ ? cmd.seq() - *last_command_seq_ - 1 : 1;
    }
    last_command_seq_ = cmd.seq();
    if (cmd.step() < resume_step_ && !cmd.stop()) continue;  // a restarted corner joins at its resume step
    if (!have_command_ || cmd.step() >= latest_command_.step()) {
      latest_command_ = cmd;
      have_command_ = true;
      if (cmd.valid() && (cmd.mode() == msg::MODE_FORCE || cmd.mode() == msg::MODE_RELEASE)) {
        // Lockstep (and the start command): the command belongs to its period's start.
        // Realtime: to its arrival on this corner's clock.
        const double at = options_.mode == ClockMode::Lockstep || !started_ ? cmd.time_s() : sim_now_s();
        watchdog_.on_command(at, cmd.mode() == msg::MODE_FORCE ? cmd.clamp_force_kN() : 0.0);
      }
    }
  }
  msg::CalibrationState state;
  while (calibration_.take(state)) {
    if (state.corner_id() != my_id_) continue;
    if (state.run_id() != participant_.run_id()) {
      ++stats_.calibrations_rejected;  // another run's
      continue;
    }
    if (state.version() < model_.version && friction_.started()) continue;  // stale
    dds::CalibrationModel m;
    if (!dds::from_msg(state, m)) {
      ++stats_.calibrations_rejected;
      continue;
    }
    if (!model_.friction.delta_rev.empty() && m.friction.delta_rev != model_.friction.delta_rev) {
      ++stats_.calibrations_rejected;  // thresholds are fixed by the calibrator config
      continue;
    }
    model_ = std::move(m);
    ++stats_.calibrations_applied;
  }
}

void CornerApp::simulate_period(std::uint64_t k) {
  const double dt = scenario_.plant_dt_s;
  scenario::ExternalInputs ext;
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
  msg::MeasurementSample m;
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
      friction = friction_.step_load_cell_excess(model_.friction, x, sim_.last().speed_rev_s, sim_.last().temperature_C);
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
  // Lockstep: an empty block still tells the CCU that this period is done (time is simulated).
  // Realtime: nothing to send is nothing sent.
  if (options_.mode == ClockMode::Lockstep || !block_.samples().empty()) {
    if (blocks_.write(block_)) {
      ++stats_.blocks_published;
      stats_.samples_published += block_.samples().size();
      if (ccu_lost_ || w.mode == faults::WatchdogMode::Holding || w.mode == faults::WatchdogMode::Default) {
        stats_.samples_without_ccu += block_.samples().size();
      }
    } else {
      ++stats_.write_failures;
    }
  }
  ++stats_.periods;
  if (periods_csv_ != nullptr) {
    std::fprintf(periods_csv_, "%.6f,%.9g,%.9g,%d,%u\n", sim_.time_s(), sim_.last().force_true_kN,
                 ext.force_command_kN ? *ext.force_command_kN : std::nan(""), static_cast<int>(w.mode),
                 options_.incarnation);
  }
}

void CornerApp::finish_stats(Clock::time_point wall0) {
  if (stats_.periods > 0) stats_.mean_jitter_s = jitter_sum_s_ / static_cast<double>(stats_.periods);
  stats_.command_deadlines_missed = commands_.deadlines_missed();
  stats_.write_failures += blocks_.write_failures();
  stats_.samples_in_flight = outbox_.size();
  stats_.first_step = resume_step_;
  stats_.wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();
  if (periods_csv_ != nullptr) std::fflush(periods_csv_);
}

void CornerApp::freeze_for_kill() {
  // The scheduled kill: keep the logs up to this instant, then stop dead. From SIGSTOP on the
  // process sends nothing (no sample, no liveliness), as after a crash; the launcher SIGKILLs it.
  if (!options_.stats_file.empty()) write_stats(options_.stats_file);
  ::raise(SIGSTOP);
  ::_exit(kExitRuntime);  // continued instead of killed: nobody carried the kill out
}

int CornerApp::run(std::string& error) {
  const auto wall0 = Clock::now();
  if (!wait_for_ccu(error)) return events_.interrupted() ? kExitOk : kExitDiscovery;
  publish_health(msg::HEALTH_STARTING);

  // Both modes start at the CCU's first command for our first period: it is the start signal.
  // A restarted corner republishes its health until then (the CCU holds the clock for it).
  auto republish = Clock::now() + std::chrono::milliseconds(200);
  const bool started = events_.wait_for(options_.discovery_timeout, [&] {
    drain_inputs();
    if (Clock::now() >= republish) {
      publish_health(msg::HEALTH_STARTING);
      republish = Clock::now() + std::chrono::milliseconds(200);
    }
    return have_command_;
  });
  if (!started) {
    if (events_.interrupted()) return kExitOk;
    error = "no start command from the CCU within " + std::to_string(options_.discovery_timeout.count()) + " ms";
    return kExitPeerLost;
  }
  const std::uint64_t first = std::max(resume_step_, latest_command_.step());
  resume_step_ = first;
  if (first > 0) sim_.start_at(static_cast<double>(first) * scenario_.ccu_period_s);
  publish_health(msg::HEALTH_RUNNING);

  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(scenario_.ccu_period_s));
  t0_ = Clock::now();
  started_ = true;
  for (std::uint64_t k = first; k < periods_; ++k) {
    if (options_.process_faults && link_.killed(sim_.time_s() + scenario_.plant_dt_s)) {
      finish_stats(wall0);
      freeze_for_kill();
    }
    if (options_.mode == ClockMode::Lockstep) {
      if (!ccu_lost_) {
        // The command for period k is the grant to simulate it. Without a CCU (its command
        // writer lost its liveliness) the corner runs on alone under its watchdog.
        const bool granted = events_.wait_for(options_.peer_timeout, [&] {
          drain_inputs();
          return latest_command_.step() >= k || latest_command_.stop() || ccu_gone();
        });
        if (events_.interrupted()) break;
        if (!granted) {
          error = "no command for period " + std::to_string(k) + " from the CCU within " +
                  std::to_string(options_.peer_timeout.count()) + " ms";
          publish_health(msg::HEALTH_FAILED);
          return kExitPeerLost;
        }
        if (latest_command_.stop()) break;
        if (latest_command_.step() < k) ccu_lost_ = true;  // only ccu_gone() ends the wait without a grant
      }
    } else {
      // Pace on the wall clock: period k starts at t0 + (k - first) * period.
      const auto wake = t0_ + period * static_cast<long long>(k - first);
      events_.wait_until(wake, [&] { return events_.interrupted(); });
      if (events_.interrupted()) break;
      const double late_s = std::chrono::duration<double>(Clock::now() - wake).count();
      jitter_sum_s_ += late_s;
      if (late_s > stats_.max_jitter_s) stats_.max_jitter_s = late_s;
      if (late_s > scenario_.ccu_period_s) ++stats_.overruns;
      drain_inputs();
      if (latest_command_.stop()) break;
    }
    simulate_period(k);
  }
  finish_stats(wall0);
  // Deliver everything before the writer goes away (nobody acknowledges without a CCU).
  const bool alone = ccu_lost_ || ccu_gone() || watchdog_.at(sim_.time_s()).mode == faults::WatchdogMode::Holding ||
                     watchdog_.at(sim_.time_s()).mode == faults::WatchdogMode::Default;
  const eprosima::fastrtps::Duration_t ack(alone ? 0 : 2, alone ? 100000000 : 0);
  blocks_.get().wait_for_acknowledgments(ack);
  publish_health(events_.interrupted() ? msg::HEALTH_FAILED : msg::HEALTH_FINISHED);
  health_.get().wait_for_acknowledgments(ack);
  stats_.wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();
  return kExitOk;
}

void CornerApp::write_stats(const std::string& file) const {
  const CornerStats& s = stats_;
  launch::StatsWriter w;
  w.set("corner", std::string(dds::corner_name(options_.corner)));
  w.set("incarnation", static_cast<unsigned long long>(options_.incarnation));
  w.set("first_step", static_cast<unsigned long long>(s.first_step));
  w.set("periods", s.periods);
  w.set("samples_published", s.samples_published);
  w.set("blocks_published", s.blocks_published);
  w.set("write_failures", s.write_failures);
  w.set("commands_received", s.commands_received);
  w.set("commands_applied", s.commands_applied);
  w.set("command_seq_gaps", s.command_seq_gaps);
  w.set("calibrations_applied", s.calibrations_applied);
  w.set("calibrations_rejected", s.calibrations_rejected);
  w.set("overruns", s.overruns);
  w.set("max_jitter_s", s.max_jitter_s);
  w.set("mean_jitter_s", s.mean_jitter_s);
  w.set("command_deadlines_missed", s.command_deadlines_missed);
  w.set("samples_suppressed", s.samples_suppressed);
  w.set("samples_delayed", s.samples_delayed);
  w.set("samples_in_flight", s.samples_in_flight);
  w.set("samples_without_ccu", s.samples_without_ccu);
  w.set("ccu_lost_s", s.ccu_lost_s);
  w.set("default_force_s", s.default_force_s);
  w.set("wall_s", s.wall_s);
  const corner::CommandGateCounts& g = gate_.counts();
  w.set("commands_clamped", static_cast<unsigned long long>(g.clamped));
  w.set("commands_refused_run", static_cast<unsigned long long>(g.refused_run));
  w.set("commands_refused_source", static_cast<unsigned long long>(g.refused_source));
  w.set("commands_refused_value", static_cast<unsigned long long>(g.refused_value));
  w.set("gate_max_force_kN", gate_.params().max_force_kN);
  w.set("foreign_runs", dds::join_peer_tags(participant_.foreign_runs()));
  w.save(file);
}

}  // namespace bbw::corner_process
