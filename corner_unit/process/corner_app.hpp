// The corner process: one e-caliper (CornerSim) at the DDS edge. Owns its DDS entities (RAII;
// construction throws DdsError), converts through bbw/dds/convert.hpp, reads the clock only to
// pace realtime runs.
#pragma once

#include <bbw/idl/bbw_msgsPubSubTypes.h>

#include <chrono>
#include <cstdio>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bbw/corner/command_gate.hpp"
#include "bbw/dds/process_cli.hpp"
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

namespace bbw::corner_process {

using dds::ClockMode;

// Mode, participant, timeouts and process_faults from dds::ProcessOptions.
struct CornerOptions : dds::ProcessOptions {
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
};

// Exit statuses (docs/distributed.md).
using dds::ExitCode;
using dds::kExitDiscovery;
using dds::kExitOk;
using dds::kExitPeerLost;
using dds::kExitRuntime;
using dds::kExitUsage;

struct CornerStats {
  std::uint64_t periods = 0;
  std::uint64_t samples_published = 0;
  std::uint64_t blocks_published = 0;
  std::uint64_t write_failures = 0;
  std::uint64_t commands_received = 0;
  std::uint64_t commands_applied = 0;
  std::uint64_t command_seq_gaps = 0;
  std::uint64_t calibrations_applied = 0;
  std::uint64_t calibrations_rejected = 0;
  std::uint64_t overruns = 0;          // realtime: started a period more than one period late
  double max_jitter_s = 0.0;           // realtime: largest wake-up lateness
  double mean_jitter_s = 0.0;
  std::uint64_t command_deadlines_missed = 0;
  std::uint64_t samples_suppressed = 0;  // not sent: injected network silence
  std::uint64_t samples_delayed = 0;     // sent late: injected network delay
  std::uint64_t samples_in_flight = 0;   // still held back by a delay at the end
  std::uint64_t samples_without_ccu = 0; // published while the CCU was lost (nobody to receive them)
  double ccu_lost_s = -1.0;              // simulated time the watchdog found the CCU lost (-1: never)
  double default_force_s = -1.0;         // ... and went to the default clamp force
  std::uint64_t first_step = 0;          // the period this incarnation started at
  double wall_s = 0.0;
};

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
  const CornerStats& stats() const { return stats_; }
  bool matched_ccu() const { return matched_ccu_; }  // the CCU's endpoints matched at least once
  void write_stats(const std::string& file) const;  // key=value (bbw/launch/stats_file.hpp)

 private:
  bool wait_for_ccu(std::string& error);
  void drain_inputs();
  void simulate_period(std::uint64_t k);
  void publish_health(std::uint8_t status);
  double sim_now_s() const;  // realtime: the corner's simulated time from the wall clock
  bool ccu_gone() const;     // the CCU's command writer lost its liveliness
  [[noreturn]] void freeze_for_kill();
  void finish_stats(std::chrono::steady_clock::time_point wall0);

  const scenario::Scenario& scenario_;
  CornerOptions options_;
  dds::Events& events_;
  scenario::CornerSim sim_;
  std::uint64_t steps_per_period_;
  std::uint64_t periods_;

  dds::Participant participant_;
  dds::Writer<msg::MeasurementBlockPubSubType> blocks_;
  dds::Writer<msg::CornerHealthPubSubType> health_;
  dds::Reader<msg::ClampCommandPubSubType> commands_;
  dds::Reader<msg::CalibrationStatePubSubType> calibration_;
  corner::CommandGate gate_;  // every received command passes here (drain_inputs)
  std::uint8_t my_id_;

  faults::FaultInjector injector_;
  faults::LinkFaults link_;
  faults::CcuWatchdog watchdog_;
  faults::DelayQueue<msg::MeasurementSample, 1024> outbox_;
  std::uint64_t resume_step_ = 0;
  std::chrono::steady_clock::time_point t0_{};  // realtime: wall time of period resume_step_
  std::FILE* periods_csv_ = nullptr;
  bool ccu_lost_ = false;   // lockstep: the corner runs on alone
  bool started_ = false;
  bool matched_ccu_ = false;
  double jitter_sum_s_ = 0.0;

  msg::MeasurementBlock block_;
  msg::ClampCommand latest_command_;
  bool have_command_ = false;
  std::optional<std::uint64_t> last_command_seq_;
  dds::CalibrationModel model_;
  calibration::FrictionTracker friction_;  // element and play states of the CCU's friction model
  CornerStats stats_;
};

}  // namespace bbw::corner_process
