#include "corner_app.hpp"

#include <cstdlib>

#include "bbw/security/dds_security.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "bbw/dds/receive_runner.hpp"
#include "bbw/dds/run_id.hpp"
#include "bbw/dds/topics.hpp"
#include "bbw/runtime/period_clock.hpp"
#include "bbw/runtime/run_stats.hpp"
#include "bbw/node/csv_log.hpp"

namespace bbw::corner_process {

namespace {

using Clock = std::chrono::steady_clock;

// Older than this, a command is stale in a hot-standby run (ten CCU periods).
constexpr auto kStaleCommand = std::chrono::milliseconds(50);
// A hot-standby run, realtime: a period begun this late is one of the corner's own stalls in its
// failover stats (the commands' deadline, as a CCU's own stalls are counted).
constexpr double kOwnStallRecorded_s = 0.010;

node::CornerNodeOptions node_options(const CornerOptions& o) {
  node::CornerNodeOptions n;
  n.corner = o.corner;
  n.scenario_index = o.scenario_index;
  n.lockstep = o.mode == ClockMode::Lockstep;
  n.schedule = o.schedule;
  n.watchdog = o.watchdog;
  n.incarnation = o.incarnation;
  n.resume_at_s = o.resume_at_s;
  n.run_id = o.participant.run_id;
  n.standby = o.standby;
  return n;
}

std::string own_partition(const CornerOptions& o) {
  return dds::corner_run_partition(security::corner_partition(static_cast<int>(dds::corner_index(o.corner))),
                                   o.participant.run_id);
}

dds::ParticipantOptions named(dds::ParticipantOptions p, dds::Corner c) {
  if (p.name.empty()) p.name = std::string("bbw_corner_") + dds::corner_name(c);
  return p;
}

}  // namespace

CornerApp::CornerApp(const scenario::Scenario& scenario, const CornerOptions& options, dds::Events& events)
    : scenario_(scenario),
      options_(options),
      events_(events),
      node_(scenario, node_options(options)),
      participant_(named(options.participant, options.corner)),
      // Measurements and health in the corner's own partition of this run (corner_FL.run_<id>,
      // bbw/dds/run_id.hpp), secure or not: the permissions grant a corner only its own
      // (docs/security.md). Its commands come in that partition too (the CCU writes each corner's there), calibration state in the run's partition run_<id>.
      blocks_(participant_, dds::kMeasurementTopic,
              dds::profiles_for(options.mode == ClockMode::Lockstep, options.standby).measurement_writer, events,
              dds::Partition{own_partition(options)}),
      health_(participant_, dds::kHealthTopic, "state_writer", events, dds::Partition{own_partition(options)}),
      // No DDS content filter on these topics: Fast DDS 2.9 evaluates DDS-SQL filters on the
      // writer by deserialising into DynamicData, which throws and catches internally on every
      // sample and made the CCU's command writes its largest cost. The node drops the other
      // corners' samples instead (4 commands per period, a few bytes each).
      commands_(participant_, dds::kCommandTopic,
                dds::profiles_for(options.mode == ClockMode::Lockstep, options.standby).command_reader, events,
                dds::Partition{own_partition(options)}),
      calibration_(participant_, dds::kCalibrationTopic, "state_reader", events,
                   dds::Partition{dds::run_partition(options.participant.run_id)}),
      owners_(scenario.ccu_period_s, options.mode == ClockMode::Lockstep) {
  if (options.vehicle) {
    vehicle_in_ = std::make_unique<dds::DdsInlet<msg::CaliperTemperaturesPubSubType>>(
        participant_, dds::kCaliperTemperatureTopic, dds::profiles_for(true).measurement_reader, events,
        dds::Partition{dds::run_partition(options.participant.run_id)});
  }
  if (!options.periods_log.empty()) {
    periods_log_ = std::make_unique<node::CornerPeriodsLog>(options.periods_log, options.incarnation);
    node_.set_observer(periods_log_.get());
  }
}

CornerApp::~CornerApp() { vehicle_in_.reset(); }

void CornerApp::publish_health(std::uint8_t status) { health_.send(node_.health(status)); }

bool CornerApp::wait_for_ccu(std::string& error) {
  const auto timeout = options_.match_timeout.count() > 0 ? options_.match_timeout : options_.discovery_timeout;
  const int ccus = options_.standby ? 2 : 1;  // a hot-standby run: both CCUs before the start
  const bool ok = events_.wait_for(timeout, [&] {
    // A vehicle run: the vehicle reads our blocks too (its reader must have matched before block 0,
    // which is not sent again), and we read its sensors. A hot-standby run: both CCUs.
    const int block_readers = ccus + (vehicle_in_ == nullptr ? 0 : 1);
    return blocks_.peers() >= block_readers && commands_.peers() >= ccus && calibration_.peers() >= ccus &&
           health_.peers() >= ccus && (vehicle_in_ == nullptr || vehicle_in_->peers() >= 1);
  });
  matched_ccu_ = ok;
  if (!ok && !events_.interrupted()) {
    error = std::string("CCU not discovered within ") +
            std::to_string(timeout.count()) + " ms (measurement readers matched: " +
            std::to_string(blocks_.peers()) + ", command writers matched: " +
            std::to_string(commands_.peers()) + ")";
  }
  return ok;
}

double CornerApp::sim_now_s() const {
  return static_cast<double>(node_.resume_step()) * scenario_.ccu_period_s +
         std::chrono::duration<double>(Clock::now() - t0_).count();
}

// Who sent the last command taken: its run id, its writer's GUID, and (until the gate has pinned
// the CCU's writer) whether the writer's participant announced itself as this run's bbw_ccu.
corner::CommandSource CornerApp::command_source() const {
  corner::CommandSource source{command_in_.run_id(), {}, false};
  const auto& handle = commands_.last_info().publication_handle;
  for (std::size_t i = 0; i < source.writer.size(); ++i) source.writer[i] = handle.value[i];
  if (!node_.gate().pinned()) {  // the announcement matters only until the CCU's writer is pinned
    std::array<std::uint8_t, 12> prefix{};
    std::copy_n(source.writer.begin(), prefix.size(), prefix.begin());
    const auto tag = participant_.peer_tag(prefix);
    source.announced_as_ccu = tag && tag->run_id == participant_.run_id() &&
                              (tag->name == "bbw_ccu" || (options_.standby && tag->name == "bbw_ccu_standby"));
  }
  return source;
}

// A hot-standby run, realtime: a command written more than kStaleCommand ago (by its source
// timestamp: the same system clock on this host and in its network namespaces) is not taken.
// After a cut, the returning CCU's last command arrives when the link comes back, and DDS may let
// it through before the CCU's lowered strength has arrived (docs/faults.md, "Who commands").
bool CornerApp::stale(const eprosima::fastdds::dds::SampleInfo& info) const {
  const auto written = std::chrono::system_clock::time_point(std::chrono::duration_cast<std::chrono::system_clock::duration>(
      std::chrono::nanoseconds(info.source_timestamp.to_ns())));
  return std::chrono::system_clock::now() - written > kStaleCommand;
}

// The role of a command's writer, from its participant's announced name (cached per writer).
runtime::CommandRole CornerApp::command_role(const std::array<std::uint8_t, 16>& writer) {
  if (have_role_ && writer == role_writer_) return role_;
  std::array<std::uint8_t, 12> prefix{};
  std::copy_n(writer.begin(), prefix.size(), prefix.begin());
  const auto tag = participant_.peer_tag(prefix);
  role_ = !tag ? runtime::CommandRole::Unknown
        : tag->name == "bbw_ccu" ? runtime::CommandRole::Primary
        : tag->name == "bbw_ccu_standby" ? runtime::CommandRole::Standby
                                         : runtime::CommandRole::Unknown;
  role_writer_ = writer;
  have_role_ = true;
  return role_;
}

bool CornerApp::ccu_gone() const {
  return (commands_.get().liveliness_lost() > 0 && commands_.get().alive_writers() == 0) || commands_.peers() == 0;
}

// Takes every waiting command and calibration state into the node.
void CornerApp::drain_inputs() {
  // Members, not locals: a message's default constructor re-registers its TypeObject.
  transport::EndpointId from = 0;
  while (commands_.take(command_in_, from)) {
    if (command_in_.corner_id() != dds::corner_index(options_.corner)) continue;  // another corner's
    if (options_.standby && options_.mode == ClockMode::Realtime && stale(commands_.last_info())) {
      ++stale_commands_;  // written too long ago: a returning CCU's last command, redelivered
      continue;
    }
    const corner::CommandSource source = command_source();
    const std::uint64_t taken_before = node_.stats().commands_taken;
    node_.on_command(command_in_, source, started_ ? sim_now_s() : 0.0);
    if (options_.standby && node_.stats().commands_taken != taken_before) {
      owners_.on_command(command_role(source.writer), command_in_.step(), command_in_.time_s(), runtime::mono_now_s());
    }
  }
  transport::EndpointId cal_from = 0;
  while (calibration_.take(state_in_, cal_from)) {
    node_.on_calibration(state_in_);
    if (options_.standby && calibration_writers_ < 2 && cal_from != calibration_writer_[0]) {
      calibration_writer_[calibration_writers_++] = cal_from;
    }
  }
  if (vehicle_in_ == nullptr) return;
  const std::size_t slot = dds::corner_index(options_.corner);
  while (vehicle_in_->take(vehicle_msg_)) {
    if (vehicle_msg_.run_id() != options_.participant.run_id) continue;
    node_.set_caliper_temperature_C(vehicle_msg_.caliper_temperature_C()[slot]);
    vehicle_step_ = std::max(vehicle_step_, static_cast<std::int64_t>(vehicle_msg_.step()));
  }
}

bool CornerApp::vehicle_ready(std::uint64_t k, std::uint64_t first) const {
  return vehicle_in_ == nullptr || k == first || vehicle_step_ >= node::caliper_temperature_step(k);
}

void CornerApp::simulate_period(std::uint64_t k) {
  if (const msg::MeasurementBlock* b = node_.simulate_period(k)) node_.block_sent(blocks_.send(*b));
}

void CornerApp::finish_stats(Clock::time_point wall0) {
  CornerStats& s = node_.stats();
  if (s.periods > 0) s.mean_jitter_s = jitter_sum_s_ / static_cast<double>(s.periods);
  const std::uint64_t failures_before = s.write_failures;
  node_.finish(0, commands_.get().deadlines_missed());
  // write_failures: the node counts refused sends; the writer's own count is the same events.
  s.write_failures = failures_before;
  s.wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();
  if (periods_log_ != nullptr) periods_log_->flush();
  write_failover_stats();
}

// A hot-standby run: whose commands this corner applied, next to its stats file
// (corner_FL.stats -> corner_FL_failover.stats).
void CornerApp::write_failover_stats() const {
  if (!options_.standby || options_.stats_file.empty()) return;
  std::string file = options_.stats_file;
  const std::string ext = ".stats";
  if (file.size() > ext.size() && file.compare(file.size() - ext.size(), ext.size(), ext) == 0) file.resize(file.size() - ext.size());
  runtime::CornerFailoverStats s = owners_.stats();
  s.corner = dds::corner_name(options_.corner);
  s.commands_stale = stale_commands_;
  s.stalls = own_stalls_.stalls;
  s.stall_intervals = own_stalls_.stall_intervals;
  runtime::save(s, file + "_failover.stats");
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
    // Lockstep with a hot-standby CCU: both CCUs have begun (each sends its initial calibration
    // states just before its first command), so neither starts far behind the corners.
    const bool both_ccus = !options_.standby || options_.mode != ClockMode::Lockstep || calibration_writers_ >= 2;
    return node_.have_command() && both_ccus;
  });
  if (!started) {
    if (events_.interrupted()) return kExitOk;
    error = "no start command from the CCU within " + std::to_string(options_.discovery_timeout.count()) + " ms";
    return kExitPeerLost;
  }
  const std::uint64_t first = node_.start();
  publish_health(msg::HEALTH_RUNNING);

  // The clock policy (bbw/runtime/period_clock.hpp): lockstep, the command for period k is the
  // grant to simulate it; realtime, period k starts at t0 + (k - first) * period.
  const auto clock = runtime::make_period_clock(options_.mode, events_, scenario_.ccu_period_s, options_.peer_timeout,
                                                /*poll_while_waiting=*/false);
  const bool lockstep = clock->mode() == ClockMode::Lockstep;
  clock->start(first);
  t0_ = clock->started_at();
  started_ = true;
  CornerStats& stats = node_.stats();
  std::uint64_t k_from = first;
  // Lockstep: the periods run on the thread that receives their grant (run_on_receive); a
  // standby run (command ownership, stale commands) and process faults stay on this loop.
  const bool on_receive = lockstep && !options_.standby && !options_.process_faults && dds::lockstep_on_receive();
  if (on_receive) {
    next_k_ = first_k_ = first;
    const auto end = dds::run_on_receive(events_, [this] { return advance_on_receive(); }, [this] { return next_k_; });
    k_from = end == dds::ReceiveRunEnd::Interrupted ? node_.periods() : next_k_;
  }
  for (std::uint64_t k = k_from; k < node_.periods(); ++k) {
    if (options_.process_faults && node_.kill_due()) {
      finish_stats(wall0);
      freeze_for_kill();
    }
    // Lockstep without a CCU (its command writer lost its liveliness): the corner runs on alone
    // under its watchdog.
    if (!lockstep || !node_.ccu_lost()) {
      // A vehicle run: also the vehicle's caliper temperatures for period k.
      const runtime::PeriodStart begun = clock->begin(k, [&] {
        drain_inputs();
        return (node_.granted(k) && vehicle_ready(k, first)) || ccu_gone() || node_.latest_command().stop();
      });
      if (begun == runtime::PeriodStart::Interrupted) break;
      if (begun == runtime::PeriodStart::TimedOut) {
        error = "no command for period " + std::to_string(k) + " from the CCU within " +
                std::to_string(options_.peer_timeout.count()) + " ms";
        publish_health(msg::HEALTH_FAILED);
        return kExitPeerLost;
      }
      if (!lockstep) {
        const double late_s = clock->late_s();
        jitter_sum_s_ += late_s;
        if (late_s > stats.max_jitter_s) stats.max_jitter_s = late_s;
        if (late_s > scenario_.ccu_period_s) ++stats.overruns;
        // Not running, this corner could take no command: not the CCU's silence (its watchdog).
        if (late_s > 0.0) {
          const double now_s = sim_now_s();
          node_.on_own_stall(now_s - late_s, now_s);
        }
        if (options_.standby && late_s >= kOwnStallRecorded_s) runtime::note_corner_stall(own_stalls_, late_s, runtime::mono_now_s());
      }
      if (node_.latest_command().stop()) break;
      if (lockstep && !node_.granted(k)) node_.set_ccu_lost();  // only ccu_gone() ends the wait without a grant
    }
    simulate_period(k);
  }
  finish_stats(wall0);
  // Deliver everything before the writer goes away (nobody acknowledges without a CCU).
  const bool alone = node_.alone() || ccu_gone();
  const eprosima::fastrtps::Duration_t ack(alone ? 0 : 2, alone ? 100000000 : 0);
  blocks_.get().get().wait_for_acknowledgments(ack);
  publish_health(events_.interrupted() ? msg::HEALTH_FAILED : msg::HEALTH_FINISHED);
  health_.get().get().wait_for_acknowledgments(ack);
  stats.wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();
  return kExitOk;
}

bool CornerApp::advance_on_receive() {
  for (;;) {
    drain_inputs();
    const std::uint64_t k = next_k_;
    // The end, a stop, a lost CCU: run()'s loop carries on at next_k_.
    if (k >= node_.periods() || node_.latest_command().stop() || node_.ccu_lost() || ccu_gone()) return true;
    if (!node_.granted(k) || !vehicle_ready(k, first_k_)) return false;  // waits for more data
    simulate_period(k);
    ++next_k_;
  }
}

void CornerApp::write_stats(const std::string& file) const {
  const CornerStats& n = node_.stats();
  runtime::CornerRunStats s;
  s.corner = std::string(dds::corner_name(options_.corner));
  s.incarnation = options_.incarnation;
  s.first_step = n.first_step;
  s.periods = n.periods;
  s.samples_published = n.samples_published;
  s.blocks_published = n.blocks_published;
  s.write_failures = n.write_failures;
  s.commands_received = n.commands_received;
  s.commands_applied = n.commands_applied;
  s.command_seq_gaps = n.command_seq_gaps;
  s.calibrations_applied = n.calibrations_applied;
  s.calibrations_rejected = n.calibrations_rejected;
  s.overruns = n.overruns;
  s.max_jitter_s = n.max_jitter_s;
  s.mean_jitter_s = n.mean_jitter_s;
  s.command_deadlines_missed = n.command_deadlines_missed;
  s.samples_suppressed = n.samples_suppressed;
  s.samples_delayed = n.samples_delayed;
  s.samples_in_flight = n.samples_in_flight;
  s.samples_without_ccu = n.samples_without_ccu;
  s.ccu_lost_s = n.ccu_lost_s;
  s.default_force_s = n.default_force_s;
  s.wall_s = n.wall_s;
  const corner::CommandGateCounts& g = node_.gate().counts();
  s.commands_clamped = g.clamped;
  s.commands_refused_run = g.refused_run;
  s.commands_refused_source = g.refused_source;
  s.commands_refused_value = g.refused_value;
  s.gate_max_force_kN = node_.gate().params().max_force_kN;
  s.foreign_runs = dds::join_peer_tags(participant_.foreign_runs());
  runtime::save(s, file);
}

}  // namespace bbw::corner_process
