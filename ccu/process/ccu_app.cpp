#include "ccu_app.hpp"

#include <signal.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "bbw/dds/convert.hpp"
#include "bbw/dds/run_id.hpp"
#include "bbw/dds/topics.hpp"
#include "bbw/faults/link_faults.hpp"
#include "bbw/launch/stats_file.hpp"
#include "bbw/security/dds_security.hpp"

namespace bbw::ccu {

namespace {

using Clock = std::chrono::steady_clock;

std::vector<CornerChannel> make_channels(const scenario::Scenario& s) {
  std::vector<CornerChannel> out;
  for (const auto& c : s.corners) {
    const auto corner = dds::parse_corner(c.name);  // CcuCore has checked the names
    CornerChannel ch;
    ch.corner = *corner;
    ch.slot = dds::corner_index(*corner);
    out.push_back(std::move(ch));
  }
  const double ratio = s.ccu_period_s / s.plant_dt_s;
  if (std::fabs(ratio - std::round(ratio)) > 1e-9 || std::round(ratio) < 1 || std::round(ratio) > msg::MAX_BLOCK_SAMPLES) {
    throw std::invalid_argument(s.file + ": ccu_period_s / plant_dt_s must be an integer in [1, 64]");
  }
  return out;
}

dds::ParticipantOptions named(dds::ParticipantOptions p) {
  if (p.name.empty()) p.name = "bbw_ccu";
  return p;
}

// The first period that starts at or after time_s.
std::uint64_t step_at(double time_s, double period_s) {
  return static_cast<std::uint64_t>(std::max(0.0, std::ceil(time_s / period_s - 1e-9)));
}

faults::CornerReading reading_from(const msg::MeasurementSample& s) {
  faults::CornerReading r;
  r.seq = s.seq();
  r.time_s = s.time_s();
  r.position_rev = s.position_rev();
  r.speed_rev_per_s = s.speed_rev_s();
  r.load_cell_kN = s.force_internal_kN();
  r.motor_current_A = s.motor_current_A();
  r.temperature_C = s.temperature_C();
  r.force_command_kN = (s.status() & msg::STATUS_FORCE_MODE) ? s.command() : std::nan("");
  return r;
}

std::uint8_t feedback_code(const std::optional<corner_unit::ForceFeedback>& f) {
  if (!f) return msg::FEEDBACK_OWN;
  return *f == corner_unit::ForceFeedback::Curve ? msg::FEEDBACK_CURVE : msg::FEEDBACK_LOAD_CELL;
}

const char* kCsvHeader =
    "time_s,seq,block_seq,position_rev,speed_rev_s,force_internal_kN,force_external_kN,force_true_kN,"
    "temperature_C,motor_current_A,command,force_mode,estimate_kN,friction_kN,curve_kN,fused_kN,valid,"
    "calibrated,source,available,accepted\n";

}  // namespace

CcuApp::CcuApp(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
               const CcuOptions& options, dds::Events& events)
    : scenario_(scenario),
      options_(options),
      events_(events),
      core_(scenario, calibrator),
      periods_(static_cast<std::uint64_t>(std::ceil(scenario.duration_s / scenario.ccu_period_s - 1e-9))),
      channels_(make_channels(scenario)),
      participant_(named(options.participant)),
      // Commands and calibration state in the run's partition, measurements and health in each
      // corner's partition of this run (bbw/dds/run_id.hpp): another run on the domain never matches.
      commands_(participant_, dds::kCommandTopic,
                dds::profiles_for(options.mode == ClockMode::Lockstep).command_writer, events,
                dds::Partition{dds::run_partition(options.participant.run_id)}),
      calibration_(participant_, dds::kCalibrationTopic, "state_writer", events,
                   dds::Partition{dds::run_partition(options.participant.run_id)}) {
  for (const auto& ch : channels_) {
    const dds::Partition partition{dds::corner_run_partition(
        security::corner_partition(static_cast<int>(ch.slot)), options.participant.run_id)};
    blocks_.push_back(std::make_unique<BlockReader>(
        participant_, dds::kMeasurementTopic,
        dds::profiles_for(options.mode == ClockMode::Lockstep).measurement_reader, events, partition));
    health_.push_back(std::make_unique<HealthReader>(participant_, dds::kHealthTopic, "state_reader", events, partition));
  }
  block_.samples().reserve(msg::MAX_BLOCK_SAMPLES);
  detections_.reserve(256);
  if (options.process_faults) {
    for (const faults::ProcessAction& a : faults::process_actions(options.schedule)) {
      if (a.target == faults::Target::CCU) {
        if (a.kind == faults::ProcessAction::Kind::Kill && !kill_at_s_) kill_at_s_ = a.at_s;
      } else if (a.kind == faults::ProcessAction::Kind::Restart) {
        restarts_.emplace_back(step_at(a.at_s, scenario.ccu_period_s), *faults::corner_slot(a.target));
      }
    }
  }
  if (options.out_dir.empty()) return;
  for (auto& ch : channels_) {
    const std::string file = options.out_dir + "/ccu_" + dds::corner_name(ch.corner) + ".csv";
    ch.csv = std::fopen(file.c_str(), "w");
    if (ch.csv == nullptr) throw std::runtime_error(file + ": cannot write");
    std::fputs(kCsvHeader, ch.csv);
  }
  const std::string file = options.out_dir + "/ccu_periods.csv";
  periods_csv_ = std::fopen(file.c_str(), "w");
  if (periods_csv_ == nullptr) throw std::runtime_error(file + ": cannot write");
  std::fputs("time_s,demand_total_kN,command_total_kN,cmd_FL,cmd_FR,cmd_RL,cmd_RR,avail_FL,avail_FR,avail_RL,avail_RR\n",
             periods_csv_);
}

CcuApp::~CcuApp() {
  // The readers go before the participant (members are destroyed after this body).
  blocks_.clear();
  health_.clear();
  for (auto& ch : channels_) {
    if (ch.csv != nullptr) std::fclose(ch.csv);
  }
  if (periods_csv_ != nullptr) std::fclose(periods_csv_);
}

CornerChannel* CcuApp::channel(std::uint8_t wire_id) {
  for (auto& ch : channels_) {
    if (dds::corner_index(ch.corner) == wire_id) return &ch;
  }
  return nullptr;
}

double CcuApp::realtime_now_s() const { return std::chrono::duration<double>(Clock::now() - t0_).count(); }

void CcuApp::drain_health() {
  msg::CornerHealth h;
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    CornerChannel& ch = channels_[i];
    while (health_[i]->take(h)) {
      if (h.run_id() != participant_.run_id()) {
        ++foreign_run_samples_;  // another run's (dropped unread)
        continue;
      }
      if (h.corner_id() != ch.slot) {
        ++ch.foreign_health;  // another corner id in this corner's partition
        continue;
      }
      if (h.incarnation() < ch.health_incarnation) continue;  // an older process's last word
      ch.health_incarnation = h.incarnation();
      ch.health = h.status();
    }
  }
}

bool CcuApp::wait_for_corners(std::string& error) {
  const int n = static_cast<int>(channels_.size());
  const bool ok = events_.wait_for(options_.discovery_timeout, [&] {
    drain_health();
    bool all = commands_.matched() >= n && calibration_.matched() >= n;
    for (std::size_t i = 0; i < channels_.size(); ++i) all = all && channels_[i].health >= 0 && blocks_[i]->matched() >= 1;
    return all;
  });
  if (!ok && !events_.interrupted()) {
    int matched_blocks = 0;
    for (const auto& r : blocks_) matched_blocks += r->matched() >= 1 ? 1 : 0;
    std::string missing;
    for (const auto& ch : channels_) {
      if (ch.health < 0) missing += (missing.empty() ? "" : ", ") + std::string(dds::corner_name(ch.corner));
    }
    error = "corners not discovered within " + std::to_string(options_.discovery_timeout.count()) +
            " ms: " + (missing.empty() ? std::string("(endpoints incomplete)") : missing) +
            " (measurement writers matched " + std::to_string(matched_blocks) + " of " + std::to_string(n) + ")";
  }
  return ok;
}

void CcuApp::send_commands(std::uint64_t step, bool stop, bool log) {
  const double t = static_cast<double>(step) * scenario_.ccu_period_s;
  const auto& plans = core_.plan(t);
  double total = 0.0;
  for (auto& ch : channels_) {
    const CornerPlan& p = plans[ch.slot];
    msg::ClampCommand c;
    c.corner_id(static_cast<std::uint8_t>(ch.slot));
    c.run_id(participant_.run_id());
    c.seq(ch.command_seq++);
    c.step(step);
    c.time_s(t);
    c.mode(p.mode == CommandMode::Force ? msg::MODE_FORCE : msg::MODE_PROFILE);
    c.clamp_force_kN(p.clamp_force_kN);
    c.valid(!stop);
    c.use_friction_comp(options_.friction_feedback);
    c.calibration_version(ch.calibration_version);
    c.friction_estimate_kN(0.0);
    c.stop(stop);
    c.feedback_override(feedback_code(p.feedback));
    c.override_curve_a_kN_per_rev3(p.curve.a);
    c.override_curve_b_kN_per_rev2(p.curve.b);
    c.override_curve_c_kN_per_rev(p.curve.c);
    c.override_curve_d_kN(p.curve.d);
    commands_.write(c);
    if (p.mode == CommandMode::Force) total += p.clamp_force_kN;
  }
  if (periods_csv_ != nullptr && !stop && log) {
    char line[512];
    int n = std::snprintf(line, sizeof(line), "%.6f,%.9g,%.9g", t, core_.demand_total_kN(t), total);
    for (std::size_t s = 0; s < kSlots; ++s) {
      const bool has = core_.has(s);
      n += std::snprintf(line + n, sizeof(line) - static_cast<std::size_t>(n), has ? ",%.9g" : ",nan",
                         has && plans[s].mode == CommandMode::Force ? plans[s].clamp_force_kN : std::nan(""));
    }
    for (std::size_t s = 0; s < kSlots; ++s) {
      n += std::snprintf(line + n, sizeof(line) - static_cast<std::size_t>(n), ",%d",
                         core_.has(s) && plans[s].available ? 1 : 0);
    }
    line[n++] = '\n';
    std::fwrite(line, 1, static_cast<std::size_t>(n), periods_csv_);
  }
}

void CcuApp::publish_calibration(CornerChannel& ch, double time_s) {
  const faults::CornerSupervisor& sup = core_.supervisor(ch.slot);
  const auto fits = sup.calibrator().stats().fits_accepted;
  const auto restarts = sup.calibrator_restarts();
  if (fits == ch.published_fits && restarts == ch.published_restarts) return;
  // A fit was accepted, or the calibrator restarted from the last good curve (a rejoin).
  ch.published_fits = fits;
  ch.published_restarts = restarts;
  ++ch.calibration_version;
  msg::CalibrationState state;
  dds::to_msg(sup.calibrator(), static_cast<std::uint8_t>(ch.slot), ch.calibration_version, time_s, state);
  state.run_id(participant_.run_id());
  calibration_.write(state);
}

void CcuApp::process_block(CornerChannel& channel_of_partition, const msg::MeasurementBlock& b,
                           const eprosima::fastdds::dds::SampleInfo& info, double arrival_s) {
  if (b.corner_id() != channel_of_partition.slot) {
    // Another corner id in this corner's partition: a corner posing as another (or as one
    // that does not exist). Dropped and counted before anything reads it.
    ++channel_of_partition.foreign_blocks;
    if (channel(b.corner_id()) == nullptr) ++unknown_corner_blocks_;
    return;
  }
  CornerChannel* ch = &channel_of_partition;
  ch->instance = info.instance_handle;
  if (!ch->have_handles || ch->writer != info.publication_handle) {
    ch->writer = info.publication_handle;
    ch->writer_alive = true;
    ch->have_handles = true;
  }
  if (b.incarnation() != ch->incarnation) {
    // A restarted process: its block and sample numbering start where it joined.
    ch->incarnation = b.incarnation();
    ch->next_block = b.block_seq();
    ch->next_sample_seq = b.samples().empty() ? 1 : b.samples().front().seq();
    ++ch->rejoins;
    core_.on_link_event(ch->slot, faults::LinkEvent::Restarted, arrival_s);
  }
  if (b.block_seq() != ch->next_block) ++ch->block_gaps;
  // Never backwards within an incarnation: an old or forged block number cannot make the
  // lockstep clock wait again for a block it already has (it stalled the run until the peer
  // timeout before).
  ch->next_block = std::max(ch->next_block, b.block_seq() + 1);
  ++ch->blocks_received;
  if (!b.samples().empty() && b.samples().front().seq() != ch->next_sample_seq) {
    ch->sample_gaps += b.samples().front().seq() > ch->next_sample_seq ? b.samples().front().seq() - ch->next_sample_seq : 1;
  }
  for (const auto& s : b.samples()) {
    ++ch->samples_received;
    ch->next_sample_seq = s.seq() + 1;
    const faults::CornerReading r = reading_from(s);
    const std::uint64_t rejected_before = core_.supervisor(ch->slot).guard().rejected();
    const SampleOutcome& o = core_.on_sample(ch->slot, r, arrival_s);
    const bool accepted = core_.supervisor(ch->slot).guard().rejected() == rejected_before;
    if (!accepted) ++ch->samples_invalid;
    if (ch->csv != nullptr) {
      // Shortest round-trip decimal form (std::to_chars): exact, and far cheaper than %.17g.
      char line[700];
      char* p = line;
      char* const last = line + sizeof(line);
      // One character is kept back for each separator, so a full buffer truncates, never overflows.
      auto put = [&](double v) {
        p = std::to_chars(p, last - 1, v).ptr;
        *p++ = ',';
      };
      auto put_u = [&](unsigned long long v) {
        p = std::to_chars(p, last - 1, v).ptr;
        *p++ = ',';
      };
      put(s.time_s());
      put_u(s.seq());
      put_u(b.block_seq());
      for (double v : {s.position_rev(), s.speed_rev_s(), s.force_internal_kN(), s.force_external_kN(),
                       s.force_true_kN(), s.temperature_C(), s.motor_current_A(), s.command()}) {
        put(v);
      }
      put_u((s.status() & msg::STATUS_FORCE_MODE) ? 1 : 0);
      const double nan = std::nan("");
      for (double v : {o.valid ? o.estimate_kN : nan, o.valid ? o.friction_kN : nan, o.valid ? o.curve_kN : nan,
                       o.valid ? o.fused_kN : nan}) {
        put(v);
      }
      put_u(o.valid ? 1 : 0);
      put_u(o.calibrated ? 1 : 0);
      put_u(static_cast<unsigned long long>(core_.supervisor(ch->slot).view().source));
      put_u(core_.supervisor(ch->slot).view().available ? 1 : 0);
      put_u(accepted ? 1 : 0);  // the sample guard let this sample through
      p[-1] = '\n';
      std::fwrite(line, 1, static_cast<std::size_t>(p - line), ch->csv);
    }
  }
  if (b.block_seq() + 1 >= periods_) ch->finished = true;
  publish_calibration(*ch, b.samples().empty() ? arrival_s : b.samples().back().time_s());
}

void CcuApp::drain_blocks(double arrival_s) {
  eprosima::fastdds::dds::SampleInfo info;
  const bool realtime = options_.mode == ClockMode::Realtime;
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    CornerChannel& ch = channels_[i];
    while (blocks_[i]->take(block_, info)) {
      if (block_.run_id() != participant_.run_id()) {
        ++foreign_run_samples_;  // another run's block: dropped before anything reads it or its rate
        continue;
      }
      if (ch.block_tokens < 1.0) {
        ++ch.blocks_over_rate;  // beyond the corner's rate: dropped unread
        continue;
      }
      ch.block_tokens -= 1.0;
      process_block(ch, block_, info, realtime ? realtime_now_s() : arrival_s);
    }
  }
}

// QoS events into link events. Realtime: at the time they happened. Lockstep: deadlines are
// not used (time is simulated: CornerSupervisor::tick finds a silent corner), and a lost
// writer is acted on only while its corner's block is missing (see run()), so a slow machine
// cannot change the result.
void CcuApp::drain_qos_events(double now_s, bool lockstep) {
  dds::QosEvent e;
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    CornerChannel& ch = channels_[i];
    while (blocks_[i]->take_event(e)) {
      // A corner that has sent its last block is done: its deadline passing and its writer
      // leaving are its normal end (they raised link_lost and process_lost on the corners that
      // finished first while the CCU still waited for another's last block).
      if (!ch.have_handles || ch.finished) continue;
      const double t = lockstep ? now_s : std::chrono::duration<double>(e.at - t0_).count();
      if (e.kind == dds::QosEvent::Kind::DeadlineMissed && e.handle == ch.instance) {
        ++ch.deadlines_missed;
        if (!lockstep) core_.on_link_event(ch.slot, faults::LinkEvent::DeadlineMissed, t);
      } else if ((e.kind == dds::QosEvent::Kind::LivelinessLost || e.kind == dds::QosEvent::Kind::WriterLost) &&
                 e.handle == ch.writer && ch.writer_alive) {
        ++ch.liveliness_lost;
        ch.writer_alive = false;
        if (!lockstep) core_.on_link_event(ch.slot, faults::LinkEvent::LivelinessLost, t);
      } else if (e.kind == dds::QosEvent::Kind::LivelinessRecovered && e.handle == ch.writer) {
        ch.writer_alive = true;
      }
    }
  }
  record_detections();
}

void CcuApp::record_detections() {
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

void CcuApp::after_period(double now_s) {
  for (auto& ch : channels_) {
    ch.block_tokens = std::min(CornerChannel::kBlockBurst, ch.block_tokens + CornerChannel::kBlocksPerPeriod);
  }
  core_.tick(now_s);
  record_detections();
}

bool CcuApp::wait_for_rejoin(CornerChannel& ch, std::uint32_t incarnation, std::string& error) {
  const bool ok = events_.wait_for(options_.discovery_timeout, [&] {
    drain_health();
    return ch.health_incarnation >= incarnation &&
           (ch.health == msg::HEALTH_STARTING || ch.health == msg::HEALTH_RUNNING);
  });
  if (ok) ch.writer_alive = true;  // its block is expected from now on
  if (!ok && !events_.interrupted()) {
    error = std::string("restarted corner ") + dds::corner_name(ch.corner) + " did not join within " +
            std::to_string(options_.discovery_timeout.count()) + " ms";
  }
  return ok;
}

void CcuApp::freeze_for_kill(double at_s) {
  // The scheduled CCU kill: keep the logs up to this instant, then stop dead. From SIGSTOP on
  // nothing is sent (not even liveliness), as after a crash; the launcher SIGKILLs us.
  sim_s_ = at_s;
  wall_s_ = std::chrono::duration<double>(Clock::now() - t0_).count();
  for (auto& ch : channels_) {
    if (ch.csv != nullptr) std::fflush(ch.csv);
  }
  if (periods_csv_ != nullptr) std::fflush(periods_csv_);
  if (!options_.out_dir.empty()) write_stats(options_.out_dir + "/ccu.stats");
  ::raise(SIGSTOP);
  // Continued instead of killed (nobody carried the kill out): stop without a word.
  ::_exit(kExitRuntime);
}

int CcuApp::run(std::string& error) {
  if (!wait_for_corners(error)) return events_.interrupted() ? kExitOk : kExitDiscovery;
  // Initial model: every corner knows the thresholds and initial curve before period 0.
  for (auto& ch : channels_) {
    msg::CalibrationState state;
    dds::to_msg(core_.supervisor(ch.slot).calibrator(), static_cast<std::uint8_t>(ch.slot), 0, 0.0, state);
    calibration_.write(state);
  }
  const double T = scenario_.ccu_period_s;
  t0_ = Clock::now();
  int rc = kExitOk;
  std::uint32_t expected_incarnation[kSlots] = {};
  if (options_.mode == ClockMode::Lockstep) {
    for (std::uint64_t k = 0; k < periods_ && !events_.interrupted(); ++k) {
      const double t_k = static_cast<double>(k) * T;
      if (kill_at_s_ && t_k >= *kill_at_s_ - 1e-9) freeze_for_kill(t_k);
      for (const auto& [step, slot] : restarts_) {
        if (step != k) continue;
        for (auto& ch : channels_) {
          if (ch.slot == slot && !wait_for_rejoin(ch, ++expected_incarnation[slot], error)) return kExitPeerLost;
        }
      }
      send_commands(k, false);
      const double t_end = t_k + T;
      // Wait until every corner's block k has arrived, or its writer is gone (a dead process).
      // A command is re-sent every 200 ms without progress: a corner that has just (re)joined
      // may have matched our writer only after it was sent.
      auto pred = [&] {
        drain_blocks(t_end);
        drain_health();
        drain_qos_events(t_end, true);
        for (const auto& ch : channels_) {
          if (ch.health == msg::HEALTH_FAILED) return true;
          if (ch.next_block <= k && ch.writer_alive) return false;
        }
        return true;
      };
      const auto give_up = Clock::now() + options_.peer_timeout;
      bool ok = false;
      for (;;) {
        ok = events_.wait_until(std::min(give_up, Clock::now() + std::chrono::milliseconds(200)), pred);
        if (ok || events_.interrupted() || Clock::now() >= give_up) break;
        send_commands(k, false, false);
      }
      for (auto& ch : channels_) {
        if (ch.health == msg::HEALTH_FAILED) {
          error = std::string("corner ") + dds::corner_name(ch.corner) + " reported failure at period " + std::to_string(k);
          rc = kExitPeerLost;
        } else if (ch.next_block <= k && !ch.writer_alive) {
          core_.on_link_event(ch.slot, faults::LinkEvent::LivelinessLost, t_end);
        }
      }
      if (rc != kExitOk) break;
      if (!ok) {
        if (events_.interrupted()) break;
        std::string late;
        for (const auto& ch : channels_) {
          if (ch.next_block <= k) late += (late.empty() ? "" : ", ") + std::string(dds::corner_name(ch.corner));
        }
        error = "no block for period " + std::to_string(k) + " within " + std::to_string(options_.peer_timeout.count()) +
                " ms from " + late;
        rc = kExitPeerLost;
        break;
      }
      after_period(t_end);
      periods_done_ = k + 1;
    }
  } else {
    // Realtime: the CCU's clock. Every period it takes what has arrived, checks deadlines and
    // sends every corner its command for the next period; QoS events are handled as they come.
    send_commands(0, false);
    for (std::uint64_t k = 1; k <= periods_ && !events_.interrupted(); ++k) {
      const auto wake = t0_ + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                  static_cast<double>(k) * T));
      events_.wait_until(wake, [&] {
        drain_blocks(0.0);
        drain_health();
        drain_qos_events(0.0, false);
        return false;
      });
      if (events_.interrupted()) break;
      const double t_k = static_cast<double>(k) * T;
      after_period(realtime_now_s());
      periods_done_ = k;
      if (k == periods_) break;
      if (kill_at_s_ && t_k >= *kill_at_s_ - 1e-9) freeze_for_kill(t_k);
      send_commands(k, false);
    }
    // The last blocks: wait briefly for every corner that is still linked.
    events_.wait_for(std::chrono::milliseconds(500), [&] {
      drain_blocks(0.0);
      drain_qos_events(0.0, false);
      for (const auto& ch : channels_) {
        const auto& m = core_.supervisor(ch.slot).monitor();
        if (!ch.finished && m.ok(faults::Part::Network) && m.ok(faults::Part::Process)) return false;
      }
      return true;
    });
    record_detections();
  }
  wall_s_ = std::chrono::duration<double>(Clock::now() - t0_).count();
  sim_s_ = static_cast<double>(periods_done_) * T;
  send_commands(periods_, true);
  commands_.get().wait_for_acknowledgments(eprosima::fastrtps::Duration_t(1, 0));
  for (auto& ch : channels_) {
    if (ch.csv != nullptr) std::fflush(ch.csv);
  }
  if (periods_csv_ != nullptr) std::fflush(periods_csv_);
  return rc;
}

void CcuApp::write_stats(const std::string& file) const {
  launch::StatsWriter w;
  w.set("mode", std::string(options_.mode == ClockMode::Lockstep ? "lockstep" : "realtime"));
  w.set("periods_planned", static_cast<unsigned long long>(periods_));
  w.set("periods_done", static_cast<unsigned long long>(periods_done_));
  w.set("sim_s", sim_s_);
  w.set("wall_s", wall_s_);
  w.set("killed_at_s", kill_at_s_ ? sim_s_ : -1.0);
  std::uint64_t deadlines = 0, liveliness = 0, lost = 0, dropped = 0, foreign = 0;
  for (const auto& r : blocks_) {
    deadlines += r->deadlines_missed();
    liveliness += r->liveliness_lost();
    lost += r->samples_lost();
    dropped += r->events_dropped();
  }
  for (const auto& ch : channels_) foreign += ch.foreign_blocks + ch.foreign_health;
  w.set("measurement_deadlines_missed", static_cast<unsigned long long>(deadlines));
  w.set("measurement_liveliness_lost", static_cast<unsigned long long>(liveliness));
  w.set("measurement_samples_lost", static_cast<unsigned long long>(lost));
  w.set("qos_events_dropped", static_cast<unsigned long long>(dropped));
  w.set("foreign_corner_samples", static_cast<unsigned long long>(foreign));
  w.set("unknown_corner_blocks", static_cast<unsigned long long>(unknown_corner_blocks_));
  w.set("foreign_run_samples", static_cast<unsigned long long>(foreign_run_samples_));
  w.set("foreign_runs", dds::join_peer_tags(participant_.foreign_runs()));
  w.set("command_write_failures", static_cast<unsigned long long>(commands_.write_failures()));
  std::string corners;
  for (const auto& ch : channels_) corners += (corners.empty() ? "" : ",") + std::string(dds::corner_name(ch.corner));
  w.set("corners", corners);
  for (const auto& ch : channels_) {
    const std::string p = std::string(dds::corner_name(ch.corner)) + ".";
    const faults::CornerSupervisor& sup = core_.supervisor(ch.slot);
    const auto& st = sup.calibrator().stats();
    w.set(p + "blocks_received", static_cast<unsigned long long>(ch.blocks_received));
    w.set(p + "samples_received", static_cast<unsigned long long>(ch.samples_received));
    w.set(p + "samples_invalid", static_cast<unsigned long long>(ch.samples_invalid));
    w.set(p + "foreign_blocks", static_cast<unsigned long long>(ch.foreign_blocks));
    w.set(p + "foreign_health", static_cast<unsigned long long>(ch.foreign_health));
    w.set(p + "blocks_over_rate", static_cast<unsigned long long>(ch.blocks_over_rate));
    w.set(p + "block_gaps", static_cast<unsigned long long>(ch.block_gaps));
    w.set(p + "sample_gaps", static_cast<unsigned long long>(ch.sample_gaps));
    w.set(p + "rejoins", static_cast<unsigned long long>(ch.rejoins));
    w.set(p + "deadlines_missed", static_cast<unsigned long long>(ch.deadlines_missed));
    w.set(p + "liveliness_lost", static_cast<unsigned long long>(ch.liveliness_lost));
    w.set(p + "guard_rejected", static_cast<unsigned long long>(sup.guard().rejected()));
    w.set(p + "calibrator_restarts", static_cast<unsigned long long>(sup.calibrator_restarts()));
    w.set(p + "fits_accepted", static_cast<unsigned long long>(st.fits_accepted));
    w.set(p + "fits_rejected", static_cast<unsigned long long>(st.fits_rejected));
    w.set(p + "cycles_detected", static_cast<unsigned long long>(st.cycles_detected));
    w.set(p + "samples_rejected", static_cast<unsigned long long>(st.samples_rejected));
    w.set(p + "first_fit_time_s", st.first_fit_time_s);
    w.set(p + "calibration_version", static_cast<unsigned long long>(ch.calibration_version));
    const auto& c = sup.calibrator().curve();
    w.set(p + "curve_a", c.a);
    w.set(p + "curve_b", c.b);
    w.set(p + "curve_c", c.c);
    w.set(p + "curve_d", c.d);
  }
  // Every detection in time order of recording: corner, finding, onset, detection time.
  w.set("detections", static_cast<unsigned long long>(detections_.size()));
  for (std::size_t i = 0; i < detections_.size(); ++i) {
    const DetectionRecord& d = detections_[i];
    const std::string p = "detection." + std::to_string(i) + ".";
    w.set(p + "corner", std::string(dds::corner_name(static_cast<dds::Corner>(d.slot))));
    w.set(p + "finding", std::string(faults::to_string(d.finding)));
    w.set(p + "part", std::string(faults::to_string(faults::part_of(d.finding))));
    w.set(p + "onset_s", d.onset_s);
    w.set(p + "detected_s", d.detected_s);
  }
  w.save(file);
}

}  // namespace bbw::ccu
