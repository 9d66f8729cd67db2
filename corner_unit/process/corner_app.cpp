#include "corner_app.hpp"

#include <cmath>
#include <stdexcept>

#include "bbw/calibration/maxwell_slip.hpp"
#include "bbw/dds/topics.hpp"

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
  return s;
}

dds::ParticipantOptions named(dds::ParticipantOptions p, dds::Corner c) {
  if (p.name.empty()) p.name = std::string("bbw_corner_") + dds::corner_name(c);
  return p;
}

}  // namespace

CornerApp::CornerApp(const scenario::Scenario& scenario, const CornerOptions& options, dds::Events& events)
    : scenario_(validated(scenario, options)),
      options_(options),
      events_(events),
      sim_(scenario, options.scenario_index),
      steps_per_period_(steps_per_period(scenario)),
      periods_(static_cast<std::uint64_t>(std::ceil(scenario.duration_s / scenario.ccu_period_s - 1e-9))),
      participant_(named(options.participant, options.corner)),
      blocks_(participant_, dds::kMeasurementTopic,
              dds::profiles_for(options.mode == ClockMode::Lockstep).measurement_writer, events),
      health_(participant_, dds::kHealthTopic, "state_writer", events),
      // No DDS content filter on these topics: Fast DDS 2.9 evaluates DDS-SQL filters on the
      // writer by deserialising into DynamicData, which throws and catches internally on every
      // sample and made the CCU's command writes its largest cost. Corners drop the other
      // corners' samples here instead (4 commands per period, a few bytes each).
      commands_(participant_, dds::kCommandTopic,
                dds::profiles_for(options.mode == ClockMode::Lockstep).command_reader, events),
      calibration_(participant_, dds::kCalibrationTopic, "state_reader", events),
      my_id_(static_cast<std::uint8_t>(dds::corner_index(options.corner))) {
  block_.corner_id(static_cast<std::uint8_t>(dds::corner_index(options.corner)));
  block_.samples().reserve(steps_per_period_);
}

void CornerApp::publish_health(std::uint8_t status) {
  msg::CornerHealth h;
  h.corner_id(static_cast<std::uint8_t>(dds::corner_index(options_.corner)));
  h.status(status);
  h.samples_published(stats_.samples_published);
  h.blocks_published(stats_.blocks_published);
  h.commands_received(stats_.commands_received);
  h.commands_applied(stats_.commands_applied);
  h.command_seq_gaps(stats_.command_seq_gaps);
  h.overruns(stats_.overruns);
  h.max_jitter_s(stats_.max_jitter_s);
  h.time_s(sim_.time_s());
  health_.write(h);
}

bool CornerApp::wait_for_ccu(std::string& error) {
  const bool ok = events_.wait_for(options_.discovery_timeout, [&] {
    return blocks_.matched() >= 1 && commands_.matched() >= 1 && calibration_.matched() >= 1 &&
           health_.matched() >= 1;
  });
  if (!ok && !events_.interrupted()) {
    error = std::string("CCU not discovered within ") +
            std::to_string(options_.discovery_timeout.count()) + " ms (measurement readers matched: " +
            std::to_string(blocks_.matched()) + ", command writers matched: " +
            std::to_string(commands_.matched()) + ")";
  }
  return ok;
}

// Takes every waiting command and calibration state; keeps the newest command.
void CornerApp::drain_inputs() {
  msg::ClampCommand cmd;
  while (commands_.take(cmd)) {
    if (cmd.corner_id() != my_id_) continue;
    ++stats_.commands_received;
    if (last_command_seq_ && cmd.seq() != *last_command_seq_ + 1) {
      stats_.command_seq_gaps += cmd.seq() > *last_command_seq_ ? cmd.seq() - *last_command_seq_ - 1 : 1;
    }
    last_command_seq_ = cmd.seq();
    if (!have_command_ || cmd.step() >= latest_command_.step()) {
      latest_command_ = cmd;
      have_command_ = true;
    }
  }
  msg::CalibrationState state;
  while (calibration_.take(state)) {
    if (state.corner_id() != my_id_) continue;
    if (state.version() < model_.version && elements_initialised_) continue;  // stale
    dds::CalibrationModel m;
    if (!dds::from_msg(state, m)) {
      ++stats_.calibrations_rejected;
      continue;
    }
    if (!model_.delta_rev.empty() && m.delta_rev != model_.delta_rev) {
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
  if (valid && latest_command_.mode() == msg::MODE_FORCE) {
    ext.force_command_kN = latest_command_.clamp_force_kN();
  } else if (valid && latest_command_.mode() == msg::MODE_RELEASE) {
    ext.force_command_kN = 0.0;
  }
  if (valid) ++stats_.commands_applied;
  const bool calibrated = model_.version > 0 && latest_command_.use_friction_comp();
  if (calibrated) ext.curve = model_.curve;

  block_.block_seq(k);
  block_.period_start_s(sim_.time_s());
  block_.samples().resize(steps_per_period_);
  for (std::uint64_t i = 0; i < steps_per_period_; ++i) {
    // Friction the load cell is believed to hold, from the CCU's Maxwell-slip model and this
    // corner's own element states (they depend only on the position history).
    const double x = sim_.last().position_rev;
    double friction = 0.0;
    if (!model_.delta_rev.empty()) {
      if (!elements_initialised_) {
        element_pos_rev_.assign(model_.delta_rev.size(), x);
        elements_initialised_ = true;
      }
      friction = calibration::elements_step(x, model_.delta_rev.data(), element_pos_rev_.data(),
                                            model_.delta_rev.size(), model_.stiffness_kN_per_rev.data(), nullptr);
    }
    ext.friction_estimate_kN = calibrated ? friction : 0.0;
    const auto& s = sim_.step(dt, ext);
    dds::to_msg(s, calibrated && sim_.feedback() == corner_unit::ForceFeedback::Compensated,
                block_.samples()[i]);
  }
  block_.first_sample_seq(block_.samples().front().seq());
  if (blocks_.write(block_)) {
    ++stats_.blocks_published;
    stats_.samples_published += steps_per_period_;
  } else {
    ++stats_.write_failures;
  }
  ++stats_.periods;
}

int CornerApp::run(std::string& error) {
  const auto wall0 = Clock::now();
  if (!wait_for_ccu(error)) return events_.interrupted() ? kExitOk : kExitDiscovery;
  publish_health(msg::HEALTH_STARTING);

  // Both modes start at the CCU's first command (step 0): it is the start signal.
  const bool started = events_.wait_for(options_.discovery_timeout, [&] {
    drain_inputs();
    return have_command_;
  });
  if (!started) {
    if (events_.interrupted()) return kExitOk;
    error = "no start command from the CCU within " + std::to_string(options_.discovery_timeout.count()) + " ms";
    return kExitPeerLost;
  }
  publish_health(msg::HEALTH_RUNNING);

  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(scenario_.ccu_period_s));
  const auto t0 = Clock::now();
  double jitter_sum = 0.0;
  for (std::uint64_t k = 0; k < periods_; ++k) {
    if (options_.mode == ClockMode::Lockstep) {
      // The command for period k is the grant to simulate it.
      const bool granted = events_.wait_for(options_.peer_timeout, [&] {
        drain_inputs();
        return latest_command_.step() >= k || latest_command_.stop();
      });
      if (events_.interrupted()) break;
      if (!granted) {
        error = "no command for period " + std::to_string(k) + " from the CCU within " +
                std::to_string(options_.peer_timeout.count()) + " ms";
        publish_health(msg::HEALTH_FAILED);
        return kExitPeerLost;
      }
      if (latest_command_.stop()) break;
    } else {
      // Pace on the wall clock: period k starts at t0 + k * period.
      const auto wake = t0 + period * static_cast<long long>(k);
      events_.wait_until(wake, [&] { return events_.interrupted(); });
      if (events_.interrupted()) break;
      const double late_s = std::chrono::duration<double>(Clock::now() - wake).count();
      jitter_sum += late_s;
      if (late_s > stats_.max_jitter_s) stats_.max_jitter_s = late_s;
      if (late_s > scenario_.ccu_period_s) ++stats_.overruns;
      drain_inputs();
      if (latest_command_.stop()) break;
    }
    simulate_period(k);
  }
  if (stats_.periods > 0) stats_.mean_jitter_s = jitter_sum / static_cast<double>(stats_.periods);
  stats_.command_deadlines_missed = commands_.deadlines_missed();
  stats_.write_failures += blocks_.write_failures();
  // Deliver everything before the writer goes away.
  blocks_.get().wait_for_acknowledgments(eprosima::fastrtps::Duration_t(2, 0));
  publish_health(events_.interrupted() ? msg::HEALTH_FAILED : msg::HEALTH_FINISHED);
  health_.get().wait_for_acknowledgments(eprosima::fastrtps::Duration_t(1, 0));
  stats_.wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();
  return kExitOk;
}

}  // namespace bbw::corner_process
