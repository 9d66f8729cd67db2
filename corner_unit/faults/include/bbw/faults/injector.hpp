// Fault injection on one corner (docs/faults.md, "Injection"). Pure: time comes from the
// readings (their time_s) or is passed in; the noise of a noise burst comes from a generator
// seeded at construction. Allocation-free after construction.
//
// Use with CornerSim:
//   FaultInjector inj(schedule, Target::FL, seed);
//   ExternalInputs ext = ...;                 // the CCU's command etc.
//   inj.prepare(ext, sim.time_s() + dt_s);    // sensor hook + torque scale for this step
//   sim.step(dt_s, ext);
// Network and process faults are not applied here; the launcher and the corner process ask
// link_faults.hpp when to stay silent, delay or die.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "bbw/faults/schedule.hpp"
#include "bbw/plant/plant.hpp"
#include "bbw/scenario/corner_sim.hpp"

namespace bbw::faults {

class FaultInjector final : public scenario::SensorHook {
 public:
  // Keeps the sensor and actuator faults of `corner` from the schedule. Throws
  // std::invalid_argument for Target::CCU.
  FaultInjector(const FaultSchedule& schedule, Target corner, std::uint64_t noise_seed);

  // SensorHook: applies the load-cell and resolver faults active at readings.time_s.
  void apply(plant::Measurement& readings) override;

  // The fraction of motor torque the actuator delivers at time_s (1 when healthy).
  double torque_scale(double time_s) const;
  // Whether the actuator is seized (jammed) at time_s.
  bool seized(double time_s) const;

  // Sets ext.sensor_hook = this, ext.torque_scale and ext.actuator_seized for a step ending at
  // step_end_s.
  void prepare(scenario::ExternalInputs& ext, double step_end_s);

  // True when any sensor or actuator fault of this corner is active at time_s.
  bool any_active(double time_s) const;
  Target corner() const { return corner_; }
  const std::vector<FaultSpec>& faults() const { return faults_; }

 private:
  Target corner_;
  std::vector<FaultSpec> faults_;     // sensor + actuator faults of this corner
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  plant::Measurement previous_;       // the previous readings as delivered
  bool have_previous_ = false;
  bool load_cell_stuck_ = false;      // a stuck fault held the previous step
  bool resolver_stuck_ = false;
  double stuck_load_cell_kN_ = 0.0;
  double stuck_position_rev_ = 0.0;
  double stuck_speed_rev_per_s_ = 0.0;
};

}  // namespace bbw::faults
