// The in-process lockstep runner: the CcuNode and one CornerNode per scenario corner, over the
// in-memory transport (bbw/transport/in_memory.hpp), in one thread. The same node cores and the
// same lockstep protocol as the DDS processes (the command for period k grants it; the CCU's
// barrier waits for every corner's block k), so a lockstep run here writes the same logs as
// `./bbw run` over Fast DDS (tests NodeDigests.*). For tests, campaigns and fast runs.
//
// Process faults (options.process_faults) are carried out as the launcher and the processes do
// them over DDS in lockstep:
// - a corner kill: the corner checks its schedule at the start of each period and stops dead
//   (nothing more is sent); the CCU misses its block, finds its writer gone and acts on the loss
//   at the end of that period (CcuNode::end_lockstep_period; over DDS the liveliness lease runs
//   out in wall time while the CCU waits, so in simulated time it is that same period);
// - a corner restart: the launcher starts the new process at once; here a new CornerNode with
//   incarnation + 1 and resume_at_s = the restart time, on new endpoints; it announces itself,
//   receives the newest calibration state of its corner (the state topic is TRANSIENT_LOCAL,
//   keep-last 1 per corner), and starts on the CCU's command for its resume period, for which
//   the CCU waits for it (CcuNode::expect_rejoin);
// - a CCU kill: from the first period starting at or after the kill, the CCU sends and reads
//   nothing; the corners find it gone instead of a grant (its command writer lost) and run on
//   alone under their watchdog (CornerNode::set_ccu_lost). A CCU restart is refused, as by the
//   launcher.
// A dead corner has no plant (it lived in the process): nothing is simulated for it until its
// new incarnation starts from a released plant.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "bbw/calibration/config.hpp"
#include "bbw/faults/ccu_watchdog.hpp"
#include "bbw/faults/fault_monitor.hpp"
#include "bbw/faults/schedule.hpp"
#include "bbw/node/ccu_node.hpp"
#include "bbw/node/corner_node.hpp"
#include "bbw/transport/in_memory.hpp"

namespace bbw::node {

struct InProcessOptions {
  bool friction_feedback = true;
  faults::FaultSchedule schedule;
  faults::CcuWatchdogParams watchdog;
  faults::MonitorParams monitor;  // the CCU's fault monitor (its actuator model comes from the scenario's plant)
  ccu::ReactionPolicy reactions;  // the CCU's reactions (defaults: the product's)
  // Carry out the schedule's process faults (kill, restart) as described above, like the
  // processes with --process-faults. False: a schedule with process faults is refused.
  bool process_faults = false;
  std::uint64_t run_id = 0;  // stamped on every message, as bbw_launch's run id over DDS
};

// A hostile channel on the in-memory link from a corner to the CCU: sees every measurement
// block on its way (channel = the CCU's channel index) and may change it before the CCU takes
// it (corrupt, add or remove samples).
using BlockTap = std::function<void(std::size_t channel, msg::MeasurementBlock& block)>;

class InProcessRun {
 public:
  // Throws std::invalid_argument (bad scenario; process faults in the schedule without
  // options.process_faults; a CCU restart).
  InProcessRun(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
               const InProcessOptions& options);
  ~InProcessRun();
  InProcessRun(const InProcessRun&) = delete;
  InProcessRun& operator=(const InProcessRun&) = delete;

  CcuNode& ccu() { return ccu_; }
  const CcuNode& ccu() const { return ccu_; }
  std::size_t corners() const { return corners_.size(); }
  // The corner's current incarnation (a restart replaces it).
  CornerNode& corner(std::size_t i) { return *corners_[i].node; }
  // Observes corner i's periods, every incarnation of it (nullptr: none).
  void set_corner_observer(std::size_t i, CornerObserver* observer);
  void set_block_tap(BlockTap tap) { tap_ = std::move(tap); }
  // Further participants (a vehicle run, issue 15): called in step(k) after every corner's period
  // and before the CCU's intake and barrier check, so a participant that needs the corners'
  // blocks of period k (the vehicle) runs its period k there and reports it to the CCU's barrier.
  void set_period_hook(std::function<void(std::uint64_t step)> hook) { period_hook_ = std::move(hook); }
  // Corner i's measurement-block topic (another subscriber, e.g. the vehicle, may read it).
  transport::InMemoryTopic<msg::MeasurementBlock>& block_topic(std::size_t i) { return *corners_[i].blocks; }

  // Process state (process faults): the CCU is up; corner i's process is up (false after a kill
  // with no restart; a restart's new process is up at once and starts at its resume period).
  bool ccu_alive() const { return ccu_alive_; }
  bool corner_alive(std::size_t i) const { return !corners_[i].dead; }
  std::uint32_t incarnation(std::size_t i) const { return corners_[i].node->incarnation(); }

  // Runs period k (commands, every corner's period, the CCU's intake and period end). Returns
  // false once the run is over (every period done).
  bool step();
  void run() {
    while (step()) {
    }
  }
  std::uint64_t periods_done() const { return next_; }

 private:
  struct CornerEnd {
    std::unique_ptr<CornerNode> node;
    std::unique_ptr<transport::InMemoryTopic<msg::MeasurementBlock>> blocks;
    std::unique_ptr<transport::InMemoryTopic<msg::CornerHealth>> health;
    std::unique_ptr<transport::Outlet<msg::MeasurementBlock>> block_out;
    std::unique_ptr<transport::Outlet<msg::CornerHealth>> health_out;
    std::unique_ptr<transport::InMemoryTopic<msg::MeasurementBlock>::Receiver> block_in;   // the CCU's
    std::unique_ptr<transport::InMemoryTopic<msg::CornerHealth>::Receiver> health_in;      // the CCU's
    std::unique_ptr<transport::InMemoryTopic<msg::ClampCommand>::Receiver> command_in;
    std::unique_ptr<transport::InMemoryTopic<msg::CalibrationState>::Receiver> calibration_in;
    transport::EndpointId block_writer = 0;
    CornerObserver* observer = nullptr;
    bool started = false;
    bool stopped = false;
    bool dead = false;                            // killed, no new incarnation (yet)
    std::optional<transport::EndpointId> lost_writer;  // killed this period: the CCU finds its writer gone
    std::optional<double> restart_at_s;           // the restart scheduled after the pending kill
    std::optional<std::uint64_t> rejoin_step;     // the CCU waits for the new incarnation from this period
    std::uint32_t expected_incarnation = 0;
    std::optional<msg::CalibrationState> last_state;  // newest state sent for this corner (late joiners)
  };
  void connect_corner(CornerEnd& c);
  void corner_period(CornerEnd& c, std::uint64_t k);
  void kill_corner(CornerEnd& c, std::size_t i);
  void ccu_intake(double t_end_s);
  void send_calibration(const msg::CalibrationState& s);

  const scenario::Scenario& scenario_;
  InProcessOptions options_;
  transport::EndpointId ccu_command_endpoint_ = 0;
  CcuNode ccu_;
  transport::InMemoryTopic<msg::ClampCommand> commands_{"ClampCommand"};
  transport::InMemoryTopic<msg::CalibrationState> calibration_{"CalibrationState"};
  std::unique_ptr<transport::Outlet<msg::ClampCommand>> command_out_;
  std::unique_ptr<transport::Outlet<msg::CalibrationState>> calibration_out_;
  std::vector<CornerEnd> corners_;
  std::vector<std::unique_ptr<CornerNode>> retired_;  // killed incarnations (their counters)
  BlockTap tap_;
  std::function<void(std::uint64_t)> period_hook_;
  std::optional<double> ccu_kill_at_s_;
  bool ccu_alive_ = true;
  // Scratch messages, reused: a message's default constructor re-registers its TypeObject.
  msg::MeasurementBlock block_;
  msg::ClampCommand command_;
  msg::CalibrationState state_;
  msg::CornerHealth health_;
  std::uint64_t next_ = 0;
  transport::EndpointId next_endpoint_ = 1;
};

}  // namespace bbw::node
