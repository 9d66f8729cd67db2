#include "ccu_app.hpp"

#include <charconv>
#include <cmath>
#include <stdexcept>

#include "bbw/dds/convert.hpp"
#include "bbw/dds/topics.hpp"
#include "bbw/launch/stats_file.hpp"

namespace bbw::ccu {

namespace {

using Clock = std::chrono::steady_clock;

std::vector<CornerChannel> make_channels(const scenario::Scenario& s, const calibration::CalibratorConfig& config) {
  std::vector<CornerChannel> out;
  bool seen[dds::kCornerCount] = {};
  for (std::size_t i = 0; i < s.corners.size(); ++i) {
    const auto c = dds::parse_corner(s.corners[i].name);
    if (!c) {
      throw std::invalid_argument(s.file + ": corner '" + s.corners[i].name +
                                  "' cannot run over DDS (names must be FL, FR, RL or RR)");
    }
    if (seen[dds::corner_index(*c)]) throw std::invalid_argument(s.file + ": corner " + s.corners[i].name + " appears twice");
    seen[dds::corner_index(*c)] = true;
    CornerChannel ch;
    ch.corner = *c;
    ch.scenario_index = i;
    ch.calibrator = std::make_unique<calibration::Calibrator>(config);
    out.push_back(std::move(ch));
  }
  if (out.empty()) throw std::invalid_argument(s.file + ": no corners");
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

const char* kCsvHeader =
    "time_s,seq,block_seq,position_rev,speed_rev_s,force_internal_kN,force_external_kN,force_true_kN,"
    "temperature_C,motor_current_A,command,force_mode,estimate_kN,friction_kN,curve_kN,fused_kN,valid,"
    "calibrated\n";

}  // namespace

CcuApp::CcuApp(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
               const CcuOptions& options, dds::Events& events)
    : scenario_(scenario),
      options_(options),
      events_(events),
      planner_(scenario),
      periods_(static_cast<std::uint64_t>(std::ceil(scenario.duration_s / scenario.ccu_period_s - 1e-9))),
      channels_(make_channels(scenario, calibrator)),
      participant_(named(options.participant)),
      blocks_(participant_, dds::kMeasurementTopic,
              dds::profiles_for(options.mode == ClockMode::Lockstep).measurement_reader, events),
      health_(participant_, dds::kHealthTopic, "state_reader", events),
      commands_(participant_, dds::kCommandTopic,
                dds::profiles_for(options.mode == ClockMode::Lockstep).command_writer, events),
      calibration_(participant_, dds::kCalibrationTopic, "state_writer", events) {
  if (!(options.fusion_weight >= 0.0 && options.fusion_weight <= 1.0)) {
    throw std::invalid_argument("fusion weight must be in [0, 1]");
  }
  block_.samples().reserve(msg::MAX_BLOCK_SAMPLES);
  for (auto& ch : channels_) {
    if (options.out_dir.empty()) continue;
    const std::string file = options.out_dir + "/ccu_" + dds::corner_name(ch.corner) + ".csv";
    ch.csv = std::fopen(file.c_str(), "w");
    if (ch.csv == nullptr) throw std::runtime_error(file + ": cannot write");
    std::fputs(kCsvHeader, ch.csv);
  }
}

CcuApp::~CcuApp() {
  for (auto& ch : channels_) {
    if (ch.csv != nullptr) std::fclose(ch.csv);
  }
}

CornerChannel* CcuApp::channel(std::uint8_t wire_id) {
  for (auto& ch : channels_) {
    if (dds::corner_index(ch.corner) == wire_id) return &ch;
  }
  return nullptr;
}

std::string CcuApp::missing_corners(bool (*pred)(const CornerChannel&)) const {
  std::string out;
  for (const auto& ch : channels_) {
    if (!pred(ch)) out += (out.empty() ? "" : ", ") + std::string(dds::corner_name(ch.corner));
  }
  return out;
}

void CcuApp::drain_health() {
  msg::CornerHealth h;
  while (health_.take(h)) {
    if (CornerChannel* ch = channel(h.corner_id())) {
      ch->health = h.status();
      if (h.status() == msg::HEALTH_FINISHED) ch->finished = true;
    }
  }
}

bool CcuApp::wait_for_corners(std::string& error) {
  const int n = static_cast<int>(channels_.size());
  const bool ok = events_.wait_for(options_.discovery_timeout, [&] {
    drain_health();
    bool all = blocks_.matched() >= n && commands_.matched() >= n && calibration_.matched() >= n;
    for (const auto& ch : channels_) all = all && ch.health >= 0;
    return all;
  });
  if (!ok && !events_.interrupted()) {
    const std::string missing = missing_corners([](const CornerChannel& c) { return c.health >= 0; });
    error = "corners not discovered within " + std::to_string(options_.discovery_timeout.count()) +
            " ms: " + (missing.empty() ? std::string("(endpoints incomplete)") : missing) +
            " (measurement writers matched " + std::to_string(blocks_.matched()) + " of " + std::to_string(n) + ")";
  }
  return ok;
}

void CcuApp::send_command(CornerChannel& ch, std::uint64_t step, bool stop) {
  const double t = static_cast<double>(step) * scenario_.ccu_period_s;
  const PlannedCommand p = planner_.at(ch.scenario_index, t);
  msg::ClampCommand c;
  c.corner_id(static_cast<std::uint8_t>(dds::corner_index(ch.corner)));
  c.seq(ch.command_seq++);
  c.step(step);
  c.time_s(t);
  c.mode(p.mode == CommandMode::Force ? msg::MODE_FORCE : msg::MODE_PROFILE);
  c.clamp_force_kN(p.clamp_force_kN);
  c.valid(!stop);
  c.use_friction_comp(options_.friction_feedback);
  c.calibration_version(ch.calibration_version);
  c.friction_estimate_kN(ch.last_friction_kN);
  c.stop(stop);
  commands_.write(c);
}

void CcuApp::process_block(const msg::MeasurementBlock& b) {
  CornerChannel* ch = channel(b.corner_id());
  if (ch == nullptr) {
    ++unknown_corner_blocks_;  // a corner id that does not exist in this scenario
    return;
  }
  if (b.block_seq() != ch->next_block) ++ch->block_gaps;
  ch->next_block = b.block_seq() + 1;
  ++ch->blocks_received;
  if (!b.samples().empty() && b.samples().front().seq() != ch->next_sample_seq) {
    ch->sample_gaps += b.samples().front().seq() > ch->next_sample_seq ? b.samples().front().seq() - ch->next_sample_seq : 1;
  }
  for (const auto& s : b.samples()) {
    ++ch->samples_received;
    ch->next_sample_seq = s.seq() + 1;
    calibration::Estimate e;
    if (dds::is_finite(s)) {
      e = ch->calibrator->update(dds::to_calibration_sample(s));
    } else {
      ++ch->samples_invalid;
    }
    if (!e.valid) e.force_kN = e.friction_kN = e.curve_force_kN = std::nan("");
    ch->last_friction_kN = e.valid ? e.friction_kN : ch->last_friction_kN;
    const double fused = e.valid ? fuse(e, s.force_internal_kN(), options_.fusion_weight) : std::nan("");
    if (ch->csv != nullptr) {
      // Shortest round-trip decimal form (std::to_chars): exact, and far cheaper than %.17g.
      char line[640];
      char* p = line;
      char* const last = line + sizeof(line);
      auto put = [&](double v) {
        p = std::to_chars(p, last, v).ptr;
        *p++ = ',';
      };
      auto put_u = [&](unsigned long long v) {
        p = std::to_chars(p, last, v).ptr;
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
      for (double v : {e.force_kN, e.friction_kN, e.curve_force_kN, fused}) put(v);
      put_u(e.valid ? 1 : 0);
      put_u(e.calibrated ? 1 : 0);
      p[-1] = '\n';
      std::fwrite(line, 1, static_cast<std::size_t>(p - line), ch->csv);
    }
  }
  if (b.block_seq() + 1 >= periods_) ch->finished = true;
  // Publish the model when a fit was accepted.
  const auto& st = ch->calibrator->stats();
  if (st.fits_accepted != ch->published_fits) {
    ch->published_fits = st.fits_accepted;
    ++ch->calibration_version;
    msg::CalibrationState state;
    dds::to_msg(*ch->calibrator, b.corner_id(), ch->calibration_version,
                b.samples().empty() ? 0.0 : b.samples().back().time_s(), state);
    calibration_.write(state);
  }
}

int CcuApp::run(std::string& error) {
  if (!wait_for_corners(error)) return events_.interrupted() ? kExitOk : kExitDiscovery;
  // Initial model: every corner knows the thresholds and initial curve before period 0.
  for (auto& ch : channels_) {
    msg::CalibrationState state;
    dds::to_msg(*ch.calibrator, static_cast<std::uint8_t>(dds::corner_index(ch.corner)), 0, 0.0, state);
    calibration_.write(state);
  }
  const auto wall0 = Clock::now();
  int rc = kExitOk;
  if (options_.mode == ClockMode::Lockstep) {
    for (std::uint64_t k = 0; k < periods_ && !events_.interrupted(); ++k) {
      for (auto& ch : channels_) send_command(ch, k, false);
      // Wait until every corner's block k has arrived.
      const bool ok = events_.wait_for(options_.peer_timeout, [&] {
        while (blocks_.take(block_)) process_block(block_);
        drain_health();
        for (const auto& ch : channels_) {
          if (ch.health == msg::HEALTH_FAILED) return true;
          if (ch.next_block <= k) return false;
        }
        return true;
      });
      for (const auto& ch : channels_) {
        if (ch.health == msg::HEALTH_FAILED) {
          error = std::string("corner ") + dds::corner_name(ch.corner) + " reported failure at period " + std::to_string(k);
          rc = kExitPeerLost;
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
      periods_done_ = k + 1;
    }
  } else {
    for (auto& ch : channels_) send_command(ch, 0, false);
    // Corners pace themselves; answer each block with the command for its next period. The
    // run ends when every corner has delivered its last block, or at a bounded wall time.
    const auto limit = wall0 + std::chrono::duration_cast<Clock::duration>(
                                   std::chrono::duration<double>(scenario_.duration_s * 1.5 + 5.0));
    events_.wait_until(limit, [&] {
      while (blocks_.take(block_)) {
        process_block(block_);
        if (CornerChannel* ch = channel(block_.corner_id()); ch != nullptr && block_.block_seq() + 1 < periods_) {
          send_command(*ch, block_.block_seq() + 1, false);
        }
      }
      drain_health();
      for (const auto& ch : channels_) {
        if (!ch.finished) return false;
      }
      return true;
    });
    std::uint64_t min_blocks = periods_;
    for (const auto& ch : channels_) min_blocks = std::min(min_blocks, ch.next_block);
    periods_done_ = min_blocks;
    if (!events_.interrupted() && periods_done_ < periods_) {
      std::string late;
      for (const auto& ch : channels_) {
        if (ch.next_block < periods_) late += (late.empty() ? "" : ", ") + std::string(dds::corner_name(ch.corner));
      }
      error = "run did not complete within its wall-time bound; incomplete corners: " + late;
      rc = kExitPeerLost;
    }
  }
  wall_s_ = std::chrono::duration<double>(Clock::now() - wall0).count();
  sim_s_ = static_cast<double>(periods_done_) * scenario_.ccu_period_s;
  for (auto& ch : channels_) send_command(ch, periods_, true);
  commands_.get().wait_for_acknowledgments(eprosima::fastrtps::Duration_t(1, 0));
  for (auto& ch : channels_) {
    if (ch.csv != nullptr) std::fflush(ch.csv);
  }
  return rc;
}

void CcuApp::write_stats(const std::string& file) const {
  launch::StatsWriter w;
  w.set("mode", std::string(options_.mode == ClockMode::Lockstep ? "lockstep" : "realtime"));
  w.set("periods_planned", static_cast<unsigned long long>(periods_));
  w.set("periods_done", static_cast<unsigned long long>(periods_done_));
  w.set("sim_s", sim_s_);
  w.set("wall_s", wall_s_);
  w.set("measurement_deadlines_missed", static_cast<unsigned long long>(blocks_.deadlines_missed()));
  w.set("measurement_liveliness_lost", static_cast<unsigned long long>(blocks_.liveliness_lost()));
  w.set("measurement_samples_lost", static_cast<unsigned long long>(blocks_.samples_lost()));
  w.set("unknown_corner_blocks", static_cast<unsigned long long>(unknown_corner_blocks_));
  w.set("command_write_failures", static_cast<unsigned long long>(commands_.write_failures()));
  std::string corners;
  for (const auto& ch : channels_) corners += (corners.empty() ? "" : ",") + std::string(dds::corner_name(ch.corner));
  w.set("corners", corners);
  for (const auto& ch : channels_) {
    const std::string p = std::string(dds::corner_name(ch.corner)) + ".";
    const auto& st = ch.calibrator->stats();
    w.set(p + "blocks_received", static_cast<unsigned long long>(ch.blocks_received));
    w.set(p + "samples_received", static_cast<unsigned long long>(ch.samples_received));
    w.set(p + "samples_invalid", static_cast<unsigned long long>(ch.samples_invalid));
    w.set(p + "block_gaps", static_cast<unsigned long long>(ch.block_gaps));
    w.set(p + "sample_gaps", static_cast<unsigned long long>(ch.sample_gaps));
    w.set(p + "fits_accepted", static_cast<unsigned long long>(st.fits_accepted));
    w.set(p + "fits_rejected", static_cast<unsigned long long>(st.fits_rejected));
    w.set(p + "cycles_detected", static_cast<unsigned long long>(st.cycles_detected));
    w.set(p + "samples_rejected", static_cast<unsigned long long>(st.samples_rejected));
    w.set(p + "first_fit_time_s", st.first_fit_time_s);
    w.set(p + "calibration_version", static_cast<unsigned long long>(ch.calibration_version));
    const auto& c = ch.calibrator->curve();
    w.set(p + "curve_a", c.a);
    w.set(p + "curve_b", c.b);
    w.set(p + "curve_c", c.c);
    w.set(p + "curve_d", c.d);
  }
  w.save(file);
}

}  // namespace bbw::ccu
