// A vehicle run in one process (lockstep, in memory): the CCU and the four corners of
// InProcessRun, plus the vehicle and the pedal as further lockstep participants of the CCU's
// barrier, and the CCU's brake functions (bbw/brake/) commanding the corners.
//
// Co-simulation partition: each corner integrates its caliper at the plant step (1 ms); the
// vehicle integrates chassis and wheel spin at the same step, inside its own participant, from
// every 1 kHz true clamp-force sample of the corners' measurement blocks of the same period (it
// subscribes to the corners' block topics, as bbw_vehicle would over DDS). Per CCU period k:
// the CCU's brake functions turn the vehicle's and pedal's sensor readings at the end of k-1 and
// its clamp-force estimates into commands for k; the corners simulate k; the vehicle simulates k
// from their forces and reports k; the pedal reports k; the CCU's barrier completes k.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "bbw/brake/brake_controller.hpp"
#include "bbw/node/in_process.hpp"
#include "bbw/vehicle/driver.hpp"
#include "bbw/vehicle/pedal.hpp"
#include "bbw/vehicle/sensors.hpp"
#include "bbw/vehicle/vehicle.hpp"
#include "bbw/vehicle_run/vehicle_nodes.hpp"
#include "bbw/vehicle_run/vehicle_scenario.hpp"

namespace bbw::vehicle_run {

// One CCU period of a vehicle run (truth and what the CCU used), for logs, plots and metrics.
struct PeriodTrace {
  double time_s = 0.0;              // end of the period
  double speed_m_s = 0.0;           // truth
  double speed_estimate_m_s = 0.0;  // the CCU's
  double x_m = 0.0, y_m = 0.0, yaw_rad = 0.0, yaw_rate_rad_s = 0.0, ax_m_s2 = 0.0, path_m = 0.0;
  double steer_rad = 0.0;
  double demand = 0.0;
  bool split_mu = false;             // the CCU's yaw-moment limitation sees split-mu
  bool stopped = false;
  std::array<double, 4> wheel_speed_m_s{};   // truth, R omega
  std::array<double, 4> slip{};              // truth, positive braking
  std::array<double, 4> mu_used{};
  std::array<double, 4> surface_mu_scale{};
  std::array<double, 4> command_kN{};        // the brake functions' command for this period
  std::array<double, 4> clamp_true_kN{};     // the caliper's true force at the period's end
  std::array<double, 4> clamp_estimate_kN{}; // the CCU's estimate at the period's start
  std::array<double, 4> brake_torque_Nm{};
  std::array<double, 4> disc_C{};
  std::array<bool, 4> abs_active{};
  std::array<double, 4> target_slip{};
};

struct VehicleRunOptions {
  node::InProcessOptions in_process;
  // The co-simulation partition (docs/vehicle.md): 1 = every plant step's clamp force reaches the
  // vehicle (the shipped partition); n > 1 = the vehicle sees only every n-th sample held in
  // between (coarser exchange, for the partition study).
  int exchange_every_samples = 1;
  // The calibration study: every corner closes its loop on this curve (e.g. the end-of-line
  // curve, CalibratorConfig::initial_curve) instead of its own feedback.
  std::optional<calibration::Curve> curve_feedback;
};

class VehicleRun {
 public:
  VehicleRun(const VehicleScenario& scenario, const calibration::CalibratorConfig& calibrator, const VehicleRunOptions& options);
  bool step();
  void run();
  node::InProcessRun& in_process() { return run_; }
  const vehicle::Vehicle& vehicle() const { return vehicle_.vehicle(); }
  const VehicleNode& vehicle_node() const { return vehicle_; }
  const std::vector<PeriodTrace>& trace() const { return trace_; }
  const brake::BrakeController& brake() const { return brake_.controller(); }
  // Simulated time at which the car stopped (-1: not yet), and its path then.
  double stop_time_s() const { return vehicle_.stop_time_s(); }
  // Time the pedal was first pressed, and the speed then.
  double brake_onset_s() const { return vehicle_.brake_onset_s(); }
  double onset_speed_m_s() const { return vehicle_.onset_speed_m_s(); }
  double onset_path_m() const { return vehicle_.onset_path_m(); }
  // Per wheel: seconds with the wheel below half the vehicle speed while above 15 km/h (1 ms steps).
  const std::array<double, 4>& wheel_lock_s() const { return vehicle_.wheel_lock_s(); }
  const std::array<double, 4>& longest_lock_s() const { return vehicle_.longest_lock_s(); }

 private:
  void vehicle_period(std::uint64_t k);

  const VehicleScenario& scenario_;
  VehicleRunOptions options_;
  node::InProcessRun run_;
  VehicleNode vehicle_;
  PedalNode pedal_;
  BrakeFunctions brake_;
  std::array<std::unique_ptr<transport::InMemoryTopic<msg::MeasurementBlock>::Receiver>, 4> blocks_in_;
  msg::MeasurementBlock block_;
  std::size_t vehicle_participant_ = 0, pedal_participant_ = 0;
  std::array<std::size_t, 4> slot_of_channel_{};
  std::array<double, 4> command_kN_{}, estimate_kN_{};
  std::vector<PeriodTrace> trace_;
};

}  // namespace bbw::vehicle_run
