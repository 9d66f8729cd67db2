// The CCU process: the DDS adapter of the CcuNode (bbw/node/ccu_node.hpp). It moves every block
// and health message received over DDS into the node, turns the DDS QoS events (deadline missed,
// liveliness lost) into the node's link events, sends the node's commands and calibration states,
// runs the clock (lockstep or realtime), and logs through an observer of the node.
#pragma once

#include <bbw/idl/bbw_msgsPubSubTypes.h>
#include <bbw/idl/bbw_vehicle_msgsPubSubTypes.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/runtime/failover_stats.hpp"
#include "bbw/runtime/process_cli.hpp"
#include "bbw/dds/corner.hpp"
#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/reader.hpp"
#include "bbw/dds/writer.hpp"
#include "bbw/faults/schedule.hpp"
#include "bbw/scenario/scenario.hpp"
#include "bbw/dds/ports.hpp"
#include "bbw/node/ccu_node.hpp"
#include "bbw/node/csv_log.hpp"
#include "bbw/vehicle_run/vehicle_nodes.hpp"

namespace bbw::ccu {

using runtime::ClockMode;

using runtime::ExitCode;
using runtime::kExitDiscovery;
using runtime::kExitOk;
using runtime::kExitPeerLost;
using runtime::kExitRuntime;
using runtime::kExitUsage;

// Mode, participant, timeouts and process_faults from runtime::ProcessOptions. With
// process_faults the CCU freezes itself (SIGSTOP) at its scheduled kill time for the launcher to
// SIGKILL it, and in lockstep holds the clock at a corner's scheduled restart until the new
// process has joined.
struct CcuOptions : runtime::ProcessOptions {
  std::string out_dir;                            // per-corner CSVs and ccu.stats; "" for none
  bool friction_feedback = true;                  // let corners use compensated feedback
  faults::MonitorParams monitor;                  // config/faults/monitor.yaml (--monitor)
  faults::FaultSchedule schedule;
  // A vehicle run (issue 15, docs/vehicle.md): the vehicle and the pedal join the lockstep
  // barrier and the CCU's brake functions command the corners. nullptr: a four-corner run.
  const vehicle_run::VehicleScenario* vehicle = nullptr;
  // With a hot-standby CCU (options.standby, issue 16): "primary" or "standby" (--role). Sets the
  // participant name (bbw_ccu / bbw_ccu_standby), the command writers' ownership strength and
  // which of the schedule's CCU faults (CCU / CCU_STANDBY) is this process's.
  std::string role = "primary";
};

class CcuApp {
 public:
  CcuApp(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
         const CcuOptions& options, dds::Events& events);
  ~CcuApp();
  CcuApp(const CcuApp&) = delete;
  CcuApp& operator=(const CcuApp&) = delete;

  int run(std::string& error);
  void write_stats(const std::string& file) const;

 private:
  bool wait_for_corners(std::string& error);
  void send_commands(std::uint64_t step, bool stop, bool log = true);
  void send_calibration_updates();
  // `step`: lockstep, the period being waited for (with a standby: blocks go in in period order).
  void drain_blocks(double arrival_s, std::optional<std::uint64_t> step = std::nullopt);
  void drain_blocks_in_order(double arrival_s, std::uint64_t step);
  void drain_qos_events(double now_s, bool lockstep);
  void drain_health();
  void linger_until_corners_done();
  bool wait_for_rejoin(std::size_t channel, std::uint32_t incarnation, std::string& error);
  [[noreturn]] void freeze_for_kill(double at_s);
  // The scheduled hang: freezes (SIGSTOP) like a kill; returns when the launcher continues it.
  void freeze_for_hang(double at_s);
  // An outage (stopped and continued, cut off): lowers this CCU's command strength
  // (dds::ccu_strength; docs/faults.md "Hand-back").
  void demote(double sim_s, const char* reason);
  void discard_unsent_commands();  // cut off: the commands waiting in the writers' histories
  std::uint32_t strength() const;
  void set_strength(std::uint32_t strength);
  void link_back();
  void write_failover_stats() const;
  double realtime_now_s() const;
  void drain_vehicle();
  // Lockstep on the receiving thread (bbw/dds/receive_runner.hpp): the period whose blocks are
  // complete is ended where the last one arrives and the next one begun (plan, commands); true
  // when run()'s loop must carry on at next_k_ (a failure, the end).
  bool lockstep_period_complete(std::uint64_t k);
  bool advance_on_receive();

  const scenario::Scenario& scenario_;
  CcuOptions options_;
  dds::Events& events_;
  node::CcuNode node_;
  std::uint64_t periods_;

  dds::Participant participant_;
  // One measurement and one health reader per corner (same index as the node's channels), each
  // in that corner's partition (corner_FL, ...): DDS Security lets a corner write only there.
  using BlockInlet = dds::DdsInlet<msg::MeasurementBlockPubSubType>;
  using HealthInlet = dds::DdsInlet<msg::CornerHealthPubSubType>;
  std::vector<std::unique_ptr<BlockInlet>> blocks_;
  std::vector<std::unique_ptr<HealthInlet>> health_;
  std::vector<eprosima::fastrtps::rtps::InstanceHandle_t> instances_;  // each corner's key instance
  using CommandOutlet = dds::DdsOutlet<msg::ClampCommandPubSubType>;
  std::vector<std::unique_ptr<CommandOutlet>> commands_;  // one per corner, in its partition
  std::uint64_t commands_discarded_ = 0;  // realtime standby run: unsent when it found itself cut off
  dds::DdsOutlet<msg::CalibrationStatePubSubType> calibration_;

  msg::MeasurementBlock block_;
  msg::CornerHealth health_in_;
  std::unique_ptr<node::CcuCsvLog> log_;
  std::chrono::steady_clock::time_point t0_{};
  double wall_s_ = 0.0;
  double sim_s_ = 0.0;
  std::uint64_t periods_done_ = 0;
  std::optional<double> kill_at_s_;                       // scheduled CCU kill
  std::optional<double> hang_at_s_;                       // scheduled CCU hang (a standby run)
  runtime::CcuFailoverStats failover_;                    // a standby run: role, strength, failure
  std::chrono::steady_clock::time_point last_send_{};     // realtime, standby run: the last command send
  std::chrono::steady_clock::time_point last_block_at_{}; // ... and the last block from any corner
  bool cut_off_ = false;                                  // realtime: no block from any corner for kCutOff_s
  std::chrono::steady_clock::time_point last_stall_at_{}; // realtime: its own last stall (a late send)
  std::chrono::steady_clock::time_point quiet_until_{};   // back from a long outage: no command until then
  std::uint32_t reannouncements_ = 0;                     // strength announced again after a cut
  // Lockstep with a standby: blocks of later periods than this CCU's, per corner (FIFO ring).
  struct Stash {
    struct Slot {
      msg::MeasurementBlock block;
      transport::EndpointId writer = 0;
    };
    std::array<Slot, 1024> slots;  // as deep as the measurement history (profile *_lockstep_standby)
    std::size_t head = 0, count = 0;
    std::optional<std::uint64_t> last_seq;  // the newest block taken from the reader
  };
  std::vector<Stash> stash_;
  std::uint64_t stash_overflows_ = 0;
  bool fell_out_ = false;     // lockstep, standby run: blocks it needs are gone; it leaves the run
  std::string fell_out_why_;
  std::vector<std::pair<std::uint64_t, std::size_t>> restarts_;  // lockstep: (step, slot)
  // A vehicle run: the vehicle's and the pedal's readings, their barrier places, the brake functions.
  std::unique_ptr<dds::DdsInlet<msg::VehicleSensorsPubSubType>> vehicle_in_;
  std::unique_ptr<dds::DdsInlet<msg::PedalSamplePubSubType>> pedal_in_;
  std::optional<vehicle_run::BrakeFunctions> brake_;
  std::size_t vehicle_participant_ = 0, pedal_participant_ = 0;
  msg::VehicleSensors vehicle_msg_;
  msg::PedalSample pedal_msg_;
  // Lockstep on the receiving thread: the period whose blocks are awaited, whether its commands
  // were sent, and a corner's failure seen there.
  std::uint64_t next_k_ = 0;
  bool next_begun_ = false;
  std::string receive_failure_;
  std::uint64_t progress_ = 0;  // periods completed on the receiving thread
};

}  // namespace bbw::ccu
