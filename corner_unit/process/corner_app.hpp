// The corner process: the DDS adapter of one CornerNode (bbw/node/corner_node.hpp). Owns its DDS
// entities (RAII; construction throws DdsError), moves messages between them and the node, reads
// the clock only to pace realtime runs, and logs the node's periods (an observer).
#pragma once

#include <bbw/idl/bbw_msgsPubSubTypes.h>
#include <bbw/idl/bbw_vehicle_msgsPubSubTypes.h>

#include <array>
#include <chrono>
#include <memory>
#include <cstdio>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bbw/runtime/command_owner.hpp"
#include "bbw/runtime/process_cli.hpp"
#include "bbw/dds/convert.hpp"
#include "bbw/dds/corner.hpp"
#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/reader.hpp"
#include "bbw/dds/writer.hpp"
#include "bbw/faults/ccu_watchdog.hpp"
#include "bbw/faults/injector.hpp"
#include "bbw/faults/link_faults.hpp"
#include "bbw/faults/schedule.hpp"
#include "bbw/scenario/corner_sim.hpp"
#include "bbw/scenario/scenario.hpp"
#include "bbw/dds/ports.hpp"
#include "bbw/node/corner_node.hpp"
#include "bbw/node/csv_log.hpp"

namespace bbw::corner_process {

using runtime::ClockMode;

// Mode, participant, timeouts and process_faults from runtime::ProcessOptions.
struct CornerOptions : runtime::ProcessOptions {
  dds::Corner corner = dds::Corner::FL;
  std::size_t scenario_index = 0;               // the corner's index in the scenario
  // Longest wait for the CCU's endpoints to match (0: discovery_timeout). With DDS Security
  // main() sets a shorter one and, when it passes, starts over with a new participant: Fast
  // DDS 2.9 sometimes loses the security handshake of one pair when several participants start
  // together and never retries it (a race in its SecurityManager, fixed upstream after 2.9,
  // eProsima/Fast-DDS#4188); a new participant is a new handshake.
  std::chrono::milliseconds match_timeout{0};
  std::string stats_file;                        // JSON with counters and jitter; "" for none
  std::string periods_log;                       // per-period CSV (truth, applied command); "" for none
  // Fault injection (docs/faults.md): sensor and actuator faults through FaultInjector, network
  // faults on the outgoing samples (LinkFaults, DelayQueue). Process faults only with
  // process_faults (the launcher carries them out): at its scheduled kill the corner freezes
  // (SIGSTOP) for the launcher to SIGKILL it.
  faults::FaultSchedule schedule;
  faults::CcuWatchdogParams watchdog;
  // A restarted process: its number and the simulated time it rejoins at (it starts at the
  // first period at or after it, from a released plant, with sample seq 1).
  std::uint32_t incarnation = 0;
  double resume_at_s = 0.0;
  // A vehicle run (issue 15): the caliper's temperature comes from bbw_vehicle's
  // CaliperTemperatures (every N periods); in lockstep the corner simulates period k once the
  // vehicle's message of node::caliper_temperature_step(k) is in.
  bool vehicle = false;
};

// Exit statuses (docs/distributed.md).
using runtime::ExitCode;
using runtime::kExitDiscovery;
using runtime::kExitOk;
using runtime::kExitPeerLost;
using runtime::kExitRuntime;
using runtime::kExitUsage;

using CornerStats = node::CornerStats;

class CornerApp {
 public:
  // Validates (throws std::invalid_argument) before any DDS entity exists, then creates them.
  CornerApp(const scenario::Scenario& scenario, const CornerOptions& options, dds::Events& events);
  ~CornerApp();
  CornerApp(const CornerApp&) = delete;
  CornerApp& operator=(const CornerApp&) = delete;

  // Runs to the end of the scenario (or a stop command, or an interrupt). Returns an ExitCode;
  // `error` explains a non-zero result.
  int run(std::string& error);
  const CornerStats& stats() const { return node_.stats(); }
  bool matched_ccu() const { return matched_ccu_; }  // the CCU's endpoints matched at least once
  void write_stats(const std::string& file) const;  // key=value (bbw/runtime/run_stats.hpp)

 private:
  bool wait_for_ccu(std::string& error);
  void drain_inputs();
  void simulate_period(std::uint64_t k);
  void publish_health(std::uint8_t status);
  double sim_now_s() const;  // realtime: the corner's simulated time from the wall clock
  bool ccu_gone() const;     // the CCU's command writer lost its liveliness
  corner::CommandSource command_source() const;
  runtime::CommandRole command_role(const std::array<std::uint8_t, 16>& writer);
  bool stale(const eprosima::fastdds::dds::SampleInfo& info) const;
  void write_failover_stats() const;
  [[noreturn]] void freeze_for_kill();
  void finish_stats(std::chrono::steady_clock::time_point wall0);
  // Lockstep on the receiving thread (bbw/dds/receive_runner.hpp): simulates every period whose
  // grant is in; true when run()'s loop must carry on at next_k_ (the end, a stop, a lost CCU).
  bool advance_on_receive();

  const scenario::Scenario& scenario_;
  CornerOptions options_;
  dds::Events& events_;
  node::CornerNode node_;

  dds::Participant participant_;
  dds::DdsOutlet<msg::MeasurementBlockPubSubType> blocks_;
  dds::DdsOutlet<msg::CornerHealthPubSubType> health_;
  dds::DdsInlet<msg::ClampCommandPubSubType> commands_;
  dds::DdsInlet<msg::CalibrationStatePubSubType> calibration_;
  // A vehicle run only: the vehicle's CaliperTemperatures (every N periods, node::caliper_temperature_step).
  std::unique_ptr<dds::DdsInlet<msg::CaliperTemperaturesPubSubType>> vehicle_in_;
  msg::CaliperTemperatures vehicle_msg_;
  std::int64_t vehicle_step_ = -1;  // newest CaliperTemperatures step applied
  bool vehicle_ready(std::uint64_t k, std::uint64_t first) const;

  std::chrono::steady_clock::time_point t0_{};  // realtime: wall time of the first period
  std::unique_ptr<node::CornerPeriodsLog> periods_log_;
  bool started_ = false;
  bool matched_ccu_ = false;
  double jitter_sum_s_ = 0.0;
  msg::ClampCommand command_in_;
  msg::CalibrationState state_in_;
  // A hot-standby run (issue 16): whose commands were applied, and the role of the last writer.
  runtime::CommandOwnerTracker owners_;
  std::array<std::uint8_t, 16> role_writer_{};
  runtime::CommandRole role_ = runtime::CommandRole::Unknown;
  bool have_role_ = false;
  std::array<transport::EndpointId, 2> calibration_writer_{};  // the CCUs heard on CalibrationState
  std::size_t calibration_writers_ = 0;
  runtime::CornerFailoverStats own_stalls_;  // realtime standby run: only its stalls fields are used
  std::uint64_t stale_commands_ = 0;  // realtime standby run: commands dropped as written too long ago
  // Lockstep on the receiving thread: the next period to simulate, and the first.
  std::uint64_t next_k_ = 0;
  std::uint64_t first_k_ = 0;
};

}  // namespace bbw::corner_process
