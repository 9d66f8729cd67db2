// The vehicle plant: a planar chassis (longitudinal, lateral, yaw) with quasi-static longitudinal
// and lateral load transfer, four wheels' spin dynamics, Magic Formula tyres with combined slip,
// a road of surfaces and a grade, aerodynamic drag and rolling resistance, and four brakes
// (torque = 2 mu_pad(T_disc) r_eff F_clamp; the disc heats with the braking power; the caliper
// follows). Pure: time advances only through step(dt_s, inputs); no allocation per step.
#pragma once

#include <array>
#include <cmath>

#include "bbw/vehicle/params.hpp"
#include "bbw/vehicle/tyre.hpp"

namespace bbw::vehicle {

struct WheelState {
  double spin_rad_s = 0.0;       // >= 0 (forward driving only)
  double angle_rad = 0.0;        // accumulated rotation (the toothed wheel's reference)
  double disc_C = 20.0;
  double caliper_C = 20.0;
};

struct VehicleState {
  double time_s = 0.0;
  double x_m = 0.0, y_m = 0.0, yaw_rad = 0.0;  // earth frame: start at the origin heading +x
  double vx_m_s = 0.0, vy_m_s = 0.0;           // body frame
  double yaw_rate_rad_s = 0.0;
  double ax_m_s2 = 0.0, ay_m_s2 = 0.0;         // body-frame acceleration of the last step
  double path_m = 0.0;                         // distance travelled
  bool stopped = false;
  std::array<WheelState, kWheels> wheels{};
};

struct VehicleInputs {
  std::array<double, kWheels> clamp_force_kN{};   // true clamp force of each caliper
  std::array<double, kWheels> drive_torque_Nm{};  // driving torque at each wheel (0: coasting)
  double steer_rad = 0.0;                         // road-wheel steering angle of the front wheels
};

// What one step produced, per wheel (for sensors, logs and the summary).
struct WheelOutput {
  double load_N = 0.0;
  double slip = 0.0;            // kappa (negative braking)
  double slip_angle_rad = 0.0;
  double longitudinal_N = 0.0;  // tyre force along the wheel
  double lateral_N = 0.0;
  double mu_used = 0.0;         // |(Fx, Fy)| / Fz
  double surface_mu_scale = 0.0;
  double brake_torque_Nm = 0.0;
  double ground_speed_m_s = 0.0;  // contact patch speed along the wheel heading
};

class Vehicle {
 public:
  // Validates (throws std::invalid_argument). The road's surface indices refer to road.surfaces.
  Vehicle(const VehicleParams& params, const RoadParams& road);

  // Starts straight ahead at speed_m_s with free-rolling wheels; discs and calipers at their
  // temperatures (per wheel).
  void reset(double speed_m_s, const std::array<double, kWheels>& disc_C, const std::array<double, kWheels>& caliper_C);

  const VehicleState& step(double dt_s, const VehicleInputs& in);

  const VehicleState& state() const { return s_; }
  const std::array<WheelOutput, kWheels>& wheels() const { return out_; }
  const VehicleParams& params() const { return p_; }
  const RoadParams& road() const { return road_; }
  double speed_m_s() const { return std::hypot(s_.vx_m_s, s_.vy_m_s); }
  // Static vertical load of a wheel on level ground, N.
  double static_load_N(std::size_t wheel) const;
  // Wheel position in the body frame (x forward, y left), m.
  double wheel_x_m(std::size_t wheel) const;
  double wheel_y_m(std::size_t wheel) const;

 private:
  void loads(double grade_cos, std::array<double, kWheels>& fz) const;

  VehicleParams p_;
  RoadParams road_;
  VehicleState s_;
  std::array<WheelOutput, kWheels> out_{};
};

}  // namespace bbw::vehicle
