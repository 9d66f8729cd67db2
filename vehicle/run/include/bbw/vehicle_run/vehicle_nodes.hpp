// The vehicle run's node cores, pure (no DDS, file, thread or clock), shared by the in-process
// run (VehicleRun) and the DDS processes (bbw_vehicle, bbw_pedal, bbw_ccu):
// - VehicleNode: the vehicle plant, its sensors and the driver; takes the corners' measurement
//   blocks of a period (their true clamp force, one sample per plant step), simulates the period
//   at the plant step and returns its VehicleSensors message; keeps the truth for the summary.
// - PedalNode: the pedal's two sensors, one PedalSample per period.
// - BrakeFunctions: the CCU's side: from the newest VehicleSensors and PedalSample and the CCU's
//   own clamp-force estimates, the clamp-force command of every corner (bbw/brake/).
#pragma once

#include <bbw/idl/bbw_msgs.h>
#include <bbw/idl/bbw_vehicle_msgs.h>

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "bbw/brake/brake_controller.hpp"
#include "bbw/node/ccu_node.hpp"
#include "bbw/vehicle/driver.hpp"
#include "bbw/vehicle/pedal.hpp"
#include "bbw/vehicle/sensors.hpp"
#include "bbw/vehicle/vehicle.hpp"
#include "bbw/vehicle_run/vehicle_scenario.hpp"

namespace bbw::vehicle_run {

// The vehicle's truth at the end of one CCU period (for logs, plots and metrics).
struct TruthRow {
  double time_s = 0.0;
  double speed_m_s = 0.0;
  double x_m = 0.0, y_m = 0.0, yaw_rad = 0.0, yaw_rate_rad_s = 0.0, ax_m_s2 = 0.0, path_m = 0.0;
  double steer_rad = 0.0;
  bool stopped = false;
  bool braking = false;                      // some brake torque applied
  std::array<double, 4> wheel_speed_m_s{};   // R omega
  std::array<double, 4> slip{};              // positive braking
  std::array<double, 4> mu_used{};
  std::array<double, 4> surface_mu_scale{};
  std::array<double, 4> clamp_true_kN{};     // at the period's end
  std::array<double, 4> brake_torque_Nm{};
  std::array<double, 4> disc_C{};
  std::array<double, 4> caliper_C{};
};

class VehicleNode {
 public:
  // exchange_every_samples: the co-simulation partition study (1: every plant step's clamp force
  // reaches the vehicle; n: every n-th, held in between).
  explicit VehicleNode(const VehicleScenario& scenario, int exchange_every_samples = 1);
  VehicleNode(const VehicleNode&) = delete;
  VehicleNode& operator=(const VehicleNode&) = delete;

  void set_run_id(std::uint64_t run_id) { sensors_.run_id(run_id); }
  // A block from the corner in `slot` (0 FL .. 3 RR) for the period being assembled.
  void on_block(std::size_t slot, const msg::MeasurementBlock& block);
  // The corner's process is gone: its caliper is assumed to release.
  void corner_lost(std::size_t slot) { lost_[slot] = true; }
  // Simulates period k of n plant steps from the blocks received since the last period.
  const msg::VehicleSensors& simulate_period(std::uint64_t k, std::size_t n);

  const vehicle::Vehicle& vehicle() const { return vehicle_; }
  const std::vector<TruthRow>& truth() const { return truth_; }
  double stop_time_s() const { return stop_time_s_; }
  double brake_onset_s() const { return onset_s_; }
  double onset_speed_m_s() const { return onset_speed_m_s_; }
  double onset_path_m() const { return onset_path_m_; }
  const std::array<double, 4>& wheel_lock_s() const { return lock_s_; }
  const std::array<double, 4>& longest_lock_s() const { return longest_lock_s_; }
  double caliper_temperature_C(std::size_t slot) const { return vehicle_.state().wheels[slot].caliper_C; }

 private:
  const VehicleScenario& scenario_;
  int every_;
  double dt_s_;
  vehicle::Vehicle vehicle_;
  vehicle::Imu imu_;
  std::vector<vehicle::WheelSpeedSensor> wheel_sensors_;
  std::optional<vehicle::Driver> driver_;
  vehicle::Pedal pedal_profile_;  // the driver's foot, for the brake onset only (no sensor read)
  std::array<std::array<double, 64>, 4> force_{};
  std::array<std::size_t, 4> received_{};
  std::array<double, 4> last_force_kN_{};
  std::array<bool, 4> lost_{};
  vehicle::VehicleInputs in_;
  msg::VehicleSensors sensors_;
  std::vector<TruthRow> truth_;
  double stop_time_s_ = -1.0;
  double onset_s_ = -1.0, onset_speed_m_s_ = 0.0, onset_path_m_ = 0.0;
  std::array<double, 4> lock_s_{}, longest_lock_s_{}, current_lock_s_{};
};

class PedalNode {
 public:
  explicit PedalNode(const VehicleScenario& scenario);
  void set_run_id(std::uint64_t run_id) { sample_.run_id(run_id); }
  const msg::PedalSample& sample(std::uint64_t k, double t_end_s);

 private:
  vehicle::Pedal pedal_;
  msg::PedalSample sample_;
};

class BrakeFunctions {
 public:
  BrakeFunctions(const brake::BrakeControlParams& params, double period_s, const vehicle::VehicleState& start);
  void on_vehicle(const msg::VehicleSensors& s);
  void on_pedal(const msg::PedalSample& p);
  // The commands for the next period from the newest readings and the CCU's estimates; also
  // hands them to the CCU (CcuNode::set_brake_commands).
  const brake::BrakeOutput& plan(node::CcuNode& ccu);
  const brake::BrakeController& controller() const { return brake_; }
  const std::array<double, 4>& estimates_kN() const { return estimate_kN_; }
  const std::array<double, 4>& commands_kN() const { return command_kN_; }

 private:
  brake::BrakeController brake_;
  double period_s_;
  brake::BrakeMeasurements meas_;
  std::array<double, 4> command_kN_{};
  std::array<double, 4> estimate_kN_{};
};

}  // namespace bbw::vehicle_run
