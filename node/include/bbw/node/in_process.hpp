// The in-process lockstep runner: the CcuNode and one CornerNode per scenario corner, over the
// in-memory transport (bbw/transport/in_memory.hpp), in one thread. The same node cores and the
// same lockstep protocol as the DDS processes (the command for period k grants it; the CCU's
// barrier waits for every corner's block k), so a lockstep run here writes the same logs as
// `./bbw run` over Fast DDS (test InProcess.LogsEqualTheDdsRun). For tests, campaigns and fast
// runs. Process faults (kill, restart) need real processes and are refused here.
#pragma once

#include <memory>
#include <vector>

#include "bbw/calibration/config.hpp"
#include "bbw/faults/ccu_watchdog.hpp"
#include "bbw/faults/schedule.hpp"
#include "bbw/node/ccu_node.hpp"
#include "bbw/node/corner_node.hpp"
#include "bbw/transport/in_memory.hpp"

namespace bbw::node {

struct InProcessOptions {
  bool friction_feedback = true;
  faults::FaultSchedule schedule;
  faults::CcuWatchdogParams watchdog;
};

class InProcessRun {
 public:
  // Throws std::invalid_argument (bad scenario, process faults in the schedule).
  InProcessRun(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
               const InProcessOptions& options);
  ~InProcessRun();
  InProcessRun(const InProcessRun&) = delete;
  InProcessRun& operator=(const InProcessRun&) = delete;

  CcuNode& ccu() { return ccu_; }
  std::size_t corners() const { return corners_.size(); }
  CornerNode& corner(std::size_t i) { return *corners_[i].node; }

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
    bool started = false;
    bool stopped = false;
  };
  void corner_period(CornerEnd& c, std::uint64_t k);
  void ccu_intake(double t_end_s);

  const scenario::Scenario& scenario_;
  CcuNode ccu_;
  transport::InMemoryTopic<msg::ClampCommand> commands_{"ClampCommand"};
  transport::InMemoryTopic<msg::CalibrationState> calibration_{"CalibrationState"};
  std::unique_ptr<transport::Outlet<msg::ClampCommand>> command_out_;
  std::unique_ptr<transport::Outlet<msg::CalibrationState>> calibration_out_;
  std::vector<CornerEnd> corners_;
  // Scratch messages, reused: a message's default constructor re-registers its TypeObject.
  msg::MeasurementBlock block_;
  msg::ClampCommand command_;
  msg::CalibrationState state_;
  msg::CornerHealth health_;
  std::uint64_t next_ = 0;
  transport::EndpointId next_endpoint_ = 1;
};

}  // namespace bbw::node
