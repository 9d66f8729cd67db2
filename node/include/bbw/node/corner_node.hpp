// CornerNode: one e-caliper's logic, pure (no DDS, file, thread or clock). Typed messages in
// (ClampCommand, CalibrationState), typed messages out (MeasurementBlock, CornerHealth); time
// is an argument. The corner process (corner_unit/process) is its DDS adapter and the in-process
// runner (bbw/node/in_process.hpp) its in-memory one: both run this same code.
//
// Per period: the watchdog turns the newest command into the force command (hold, then the
// default, when the CCU is lost), the corner's friction tracker replays the CCU's friction model
// on the position history for compensated feedback, the fault injector acts on sensors and
// actuator, CornerSim steps plant + local controller, and link faults (silence, delay) act on
// the outgoing samples. Logging is an observer (CornerObserver), not part of the node.
#pragma once

#include <bbw/idl/bbw_msgs.h>
#include <bbw/idl/bbw_vehicle_msgs.h>

#include <array>
#include <cstdint>
#include <limits>
#include <optional>

#include "bbw/dds/convert.hpp"
#include "bbw/faults/ccu_watchdog.hpp"
#include "bbw/faults/injector.hpp"
#include "bbw/faults/link_faults.hpp"
#include "bbw/faults/schedule.hpp"
#include "bbw/common/corner.hpp"
#include "bbw/corner/command_gate.hpp"
#include "bbw/scenario/corner_sim.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::node {

// A vehicle run (issue 15): the vehicle sends the calipers' temperatures at the end of every N-th
// period only (N = msg::CALIPER_TEMPERATURE_EVERY_PERIODS: periods N - 1, 2N - 1, ...).
inline bool caliper_temperature_sent_after(std::uint64_t step) {
  return (step + 1) % msg::CALIPER_TEMPERATURE_EVERY_PERIODS == 0;
}
// The step whose temperatures period k's plant uses: the newest sent step below k, or -1 (none
// yet: the scenario's temperature) for the first N periods. Over DDS a corner waits for it; in
// process the run applies each sent step from the next period on, which is the same.
inline std::int64_t caliper_temperature_step(std::uint64_t k) {
  const std::uint64_t n = msg::CALIPER_TEMPERATURE_EVERY_PERIODS;
  return static_cast<std::int64_t>((k / n) * n) - 1;
}

struct CornerNodeOptions {
  Corner corner = Corner::FL;
  std::size_t scenario_index = 0;  // the corner's index in the scenario
  bool lockstep = true;            // commands belong to their period's start (else to their arrival)
  faults::FaultSchedule schedule;  // this corner's sensor, actuator and network faults
  faults::CcuWatchdogParams watchdog;
  // A restarted process: its number and the simulated time it rejoins at (it starts at the
  // first period at or after it, from a released plant, with sample seq 1).
  std::uint32_t incarnation = 0;
  double resume_at_s = 0.0;
  // The run this corner belongs to (bbw_launch's run id; 0 in process): stamped on every block and
  // health message; commands and calibration states of another run are refused.
  std::uint64_t run_id = 0;
  // A run with a hot-standby CCU (issue 16): the gate pins both CCUs' command writers, and in
  // realtime a command from another writer than the last one (a takeover: DDS ownership chose
  // it) is taken even if its period number is lower (the two CCUs' clocks start apart).
  bool standby = false;
};

struct CornerStats {
  std::uint64_t periods = 0;
  std::uint64_t samples_published = 0;
  std::uint64_t blocks_published = 0;
  std::uint64_t write_failures = 0;
  std::uint64_t commands_received = 0;
  std::uint64_t commands_applied = 0;
  std::uint64_t commands_taken = 0;    // became the newest command (a hot-standby run's owner record)
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
  std::uint64_t samples_without_ccu = 0; // published after the scheduled CCU kill (nobody to receive them)
  double ccu_lost_s = -1.0;              // simulated time the watchdog found the CCU lost (-1: never)
  double default_force_s = -1.0;         // ... and went to the default clamp force
  std::uint64_t first_step = 0;          // the period this incarnation started at
  double wall_s = 0.0;
};

// What the node did in one period, for loggers.
struct PeriodRecord {
  double time_s = 0.0;          // end of the period
  double force_true_kN = 0.0;   // simulation truth at the end
  std::optional<double> applied_kN;  // the force command the local loop was given
  faults::WatchdogMode watchdog_mode = faults::WatchdogMode::Normal;
  std::uint32_t incarnation = 0;
};

class CornerObserver {
 public:
  virtual ~CornerObserver() = default;
  virtual void on_period(const PeriodRecord& record) = 0;
};

class CornerNode {
 public:
  // Validates (throws std::invalid_argument: corner name, period ratio, resume time).
  CornerNode(const scenario::Scenario& scenario, const CornerNodeOptions& options);
  CornerNode(const CornerNode&) = delete;
  CornerNode& operator=(const CornerNode&) = delete;

  void set_observer(CornerObserver* observer) { observer_ = observer; }

  // Inputs. `arrival_s`: the corner's simulated time when the command arrived (used in realtime
  // once started; lockstep commands belong to their period's start, cmd.time_s()). Every command
  // for this corner passes the CommandGate first (run id, the pinned CCU writer, the caliper's
  // rated force range and rate; issue 17): `source` says who sent it.
  void on_command(const msg::ClampCommand& command, const corner::CommandSource& source, double arrival_s);
  void on_calibration(const msg::CalibrationState& state);
  // Realtime: this corner did not run from from_s to to_s (a period begun late; the same clock
  // as arrival_s). The watchdog does not count it as the CCU's silence (CcuWatchdog::on_own_stall).
  void on_own_stall(double from_s, double to_s) { watchdog_.on_own_stall(from_s, to_s); }
  // A vehicle run (issue 15): the caliper's temperature as the vehicle computes it from the brake
  // disc, applied from the next period on; NaN (the default) keeps the scenario's conditions.
  void set_caliper_temperature_C(double temperature_C) { caliper_temperature_C_ = temperature_C; }
  double caliper_temperature_C() const { return caliper_temperature_C_; }

  // Starts at the CCU's first command for our first period (the start signal). Returns the first
  // period to simulate.
  std::uint64_t start();
  // Simulates period k; returns the block to send, or nullptr when there is nothing to send
  // (realtime with every sample held back or silenced). The adapter reports the send's outcome.
  const msg::MeasurementBlock* simulate_period(std::uint64_t k);
  void block_sent(bool ok);
  msg::CornerHealth health(std::uint8_t status) const;
  // Lockstep only: the CCU is gone; the corner runs on alone under its watchdog.
  void set_ccu_lost() { ccu_lost_ = true; }
  // Counters the adapter owns (jitter, overruns, transport failures, wall time) go here too.
  CornerStats& stats() { return stats_; }
  const CornerStats& stats() const { return stats_; }
  // Finishes the counters at the end of a run.
  void finish(std::uint64_t transport_write_failures, std::uint64_t command_deadlines_missed);

  const corner::CommandGate& gate() const { return gate_; }
  bool have_command() const { return have_command_; }
  const msg::ClampCommand& latest_command() const { return latest_command_; }
  // Lockstep: the command for period k (the grant to simulate it) or a stop is held, and the
  // calibration state that command names (ClampCommand.calibration_version) has arrived: the two
  // come on separate topics, so on separate Fast DDS threads and in no fixed order, and a period
  // simulated before its state would differ from run to run.
  bool granted(std::uint64_t k) const {
    return latest_command_.stop() ||
           (latest_command_.step() >= k && calibration_seen_ >= latest_command_.calibration_version());
  }
  bool ccu_lost() const { return ccu_lost_; }
  // The corner runs without the CCU (lost, holding or at its default force) at its current time.
  bool alone() const;
  // The process kill scheduled for the next step is due (process faults).
  bool kill_due() const;
  std::uint64_t periods() const { return periods_; }
  std::uint64_t resume_step() const { return resume_step_; }
  double time_s() const { return sim_.time_s(); }
  double period_s() const { return scenario_.ccu_period_s; }
  Corner corner() const { return options_.corner; }
  std::uint32_t incarnation() const { return options_.incarnation; }

 private:
  const scenario::Scenario& scenario_;
  CornerNodeOptions options_;
  scenario::CornerSim sim_;
  std::uint64_t steps_per_period_;
  std::uint64_t periods_;
  std::uint8_t my_id_;

  corner::CommandGate gate_;
  faults::FaultInjector injector_;
  faults::LinkFaults link_;
  faults::CcuWatchdog watchdog_;
  faults::DelayQueue<msg::MeasurementSample, 1024> outbox_;
  std::uint64_t resume_step_ = 0;
  bool ccu_lost_ = false;
  std::optional<double> ccu_kill_at_s_;  // the schedule's CCU kill, if any
  bool started_ = false;
  faults::WatchdogMode last_mode_ = faults::WatchdogMode::Normal;

  msg::MeasurementBlock block_;
  msg::MeasurementSample sample_;
  msg::ClampCommand latest_command_;
  bool have_command_ = false;
  std::uint64_t calibration_seen_ = 0;  // newest CalibrationState.version of this run and corner (applied or not)
  std::optional<std::uint64_t> last_command_seq_;
  std::array<std::uint8_t, 16> last_writer_{};  // of the newest command taken
  dds::CalibrationModel model_;
  dds::CalibrationModel candidate_;
  calibration::FrictionTracker friction_;  // element and play states of the CCU's friction model
  CornerStats stats_;
  CornerObserver* observer_ = nullptr;
  double caliper_temperature_C_ = std::numeric_limits<double>::quiet_NaN();
};

// The number of plant steps in one CCU period; throws std::invalid_argument unless it is an
// integer in [1, MAX_BLOCK_SAMPLES].
std::uint64_t steps_per_period(const scenario::Scenario& scenario);
// The number of CCU periods in the scenario.
std::uint64_t periods_of(const scenario::Scenario& scenario);

}  // namespace bbw::node
