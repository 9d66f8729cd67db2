// The CCU's brake functions for one period, from measurements only: the driver's demand from the
// pedal's two sensors, the vehicle speed estimate, the brake-force distribution with load
// transfer (the ideal front/rear split at the measured deceleration), the per-wheel slip
// controllers, the yaw-moment limitation on split-mu (the front high side builds up at a limited
// rate above the low side; the rear axle is select-low), and the wheel torque turned into a
// clamp-force command through the CCU's brake model (2 mu_pad r_eff). Pure, no allocation per
// period; dt passed in.
#pragma once

#include <array>
#include <cstdint>

#include "bbw/brake/params.hpp"
#include "bbw/brake/slip_controller.hpp"
#include "bbw/brake/speed_estimator.hpp"

namespace bbw::brake {

struct BrakeMeasurements {
  std::array<double, 4> wheel_rad_s{};      // FL, FR, RL, RR wheel-speed sensors
  double ax_m_s2 = 0.0;                     // IMU
  double ay_m_s2 = 0.0;
  double yaw_rate_rad_s = 0.0;
  double steer_rad = 0.0;                   // steering-angle sensor (road wheel, left positive)
  double pedal_travel_mm = 0.0;             // pedal sensor 1
  double pedal_force_N = 0.0;               // pedal sensor 2
  std::array<double, 4> clamp_estimate_kN{};  // the CCU's clamp-force estimate per corner
  std::array<bool, 4> available{true, true, true, true};
};

struct PedalDemand {
  double demand = 0.0;           // 0..1 of full travel
  bool sensors_disagree = false;
};

PedalDemand pedal_demand(const PedalDemandParams& p, double travel_mm, double force_N);

struct BrakeOutput {
  std::array<double, 4> clamp_force_kN{};
  std::array<double, 4> torque_Nm{};
  std::array<WheelDecision, 4> wheels{};
  double demand = 0.0;
  double decel_request_g = 0.0;
  double speed_estimate_m_s = 0.0;
  bool split_mu = false;
  bool yaw_limited = false;      // split-mu or a lost corner's yaw limitation acts
  std::uint64_t pedal_disagreements = 0;
};

class BrakeController {
 public:
  explicit BrakeController(const BrakeControlParams& p);  // validates
  const BrakeOutput& update(double dt_s, const BrakeMeasurements& m);
  const BrakeOutput& last() const { return out_; }
  const BrakeControlParams& params() const { return p_; }
  // The mass the request and the load transfer use (the nominal one unless the estimate, less its
  // deadband, is above it) and the estimate itself.
  double mass_used_kg() const;
  double mass_estimate_kg() const { return mass_kg_; }
  // Wheel torque to clamp force through the CCU's brake model, and back.
  double clamp_kN(std::size_t wheel, double torque_Nm) const;
  double torque_Nm(std::size_t wheel, double clamp_kN) const;

 private:
  BrakeControlParams p_;
  SpeedEstimator speed_;
  std::array<SlipController, 4> slip_;
  double ax_filt_ = 0.0;
  std::array<double, 2> ax_past_m_s2_{};  // the last two periods' decelerations, newest first
  double ax_mass_filt_ = 0.0;            // the one two periods ago, through ax_filt_'s filter
  double mass_kg_ = 0.0;                // the mass estimate (MassEstimateParams), from the nominal mass
  std::array<double, 4> load_in_N_{};   // the loads the slip controllers were given last period
  std::array<double, 4> pads_off_s_{};  // how long each wheel's pads have been off the disc (WheelBrakeStatus)
  static std::size_t lost_corner(const BrakeMeasurements& m);  // the one unavailable corner, else 4
  double split_s_ = 0.0;        // time since split-mu was detected
  double lost_s_ = 0.0;         // time since a lost corner's yaw limitation began
  bool split_ = false;
  double heading_error_rad_ = 0.0;
  double brake_steer_rad_ = 0.0;        // the steering angle when the split was seen
  double brake_driver_yaw_rate_ = 0.0;  // the driver's yaw rate when the split was seen  // yaw-rate error integrated while split_
  std::size_t low_side_ = 0;    // the front wheel on the low mu, latched while split_
  // Per axle, the yaw-moment build-up delay before the split is seen (pre_split_ramp_Nm_per_s).
  struct PreSplitHold {
    bool holding = false;
    bool done = false;          // once per stop
    std::size_t wheel = 0;      // the wheel held (its partner is under slip control)
    double s = 0.0;             // time held
    double hold_Nm = 0.0;       // its applied torque when the hold began
  };
  std::array<PreSplitHold, 2> pre_{};
  BrakeOutput out_;
};

}  // namespace bbw::brake
