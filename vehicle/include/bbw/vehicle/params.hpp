// The vehicle around the brakes: parameters (plain structs, validated). Sources, cited in
// docs/vehicle.md: the tyre is the Pacejka 2002 passenger-car set of Project Chrono's sedan
// (Sedan_Pac02Tire.tir, 245/40R18, FNOMIN 4850 N) with the combined-slip terms of the same tyre
// family from CommonRoad's BMW 320i set (ADAMS handbook); the chassis is CommonRoad's BMW 320i
// (vehicle 2: mass, axle distances, track widths, CG height, yaw inertia, wheel radius and
// inertia). The config file is config/vehicle/sedan.yaml; its loader is bbw/vehicle/params_yaml.hpp.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace bbw::vehicle {

// Wheel order everywhere: FL, FR, RL, RR (bbw::Corner's order).
inline constexpr std::size_t kWheels = 4;
inline bool is_front(std::size_t wheel) { return wheel < 2; }
inline bool is_left(std::size_t wheel) { return wheel % 2 == 0; }

// Magic Formula 2002 coefficients (dimensionless unless named). Shift terms (P*H*, P*V*, R*H*,
// R*V*, RBY3) are left out so the tyre is symmetric left/right and in drive/brake: a straight
// stop on a uniform road stays straight.
struct TyreParams {
  double nominal_load_N = 4850.0;  // FNOMIN
  double pcx1 = 1.6411, pdx1 = 1.1739, pdx2 = -0.16395, pex1 = 0.46403, pex2 = 0.25022, pex3 = 0.067842;
  double pkx1 = 22.303, pkx2 = 0.48896, pkx3 = 0.21253;
  double pcy1 = 1.3507, pdy1 = 1.0489, pdy2 = -0.18033, pey1 = -0.0074722, pky1 = 21.92, pky2 = 2.0012;
  double rbx1 = 13.276, rbx2 = -13.778, rcx1 = 1.2568, rex1 = 0.65225;
  double rby1 = 7.1433, rby2 = 9.1916, rcy1 = 1.0719, rey1 = -0.27572;

  void validate() const;  // throws std::invalid_argument naming the field, value and rule
};

struct ChassisParams {
  double mass_kg = 1093.3;              // CommonRoad vehicle 2 (BMW 320i), total mass
  double yaw_inertia_kg_m2 = 1791.6;
  double cg_to_front_axle_m = 1.1562;
  double cg_to_rear_axle_m = 1.4227;
  double track_front_m = 1.3868;
  double track_rear_m = 1.3640;
  double cg_height_m = 0.5749;
  double front_roll_share = 0.55;       // share of lateral load transfer taken by the front axle
  double wheel_radius_m = 0.344;
  double wheel_inertia_kg_m2 = 1.7;
  double drag_coefficient = 0.30;       // Cd
  double frontal_area_m2 = 2.2;
  double air_density_kg_m3 = 1.2;
  double rolling_resistance = 0.013;    // f_r: rolling resistance force / normal load
  double slip_speed_floor_m_s = 1.0;    // slip denominators never below this (low-speed damping)
  double stop_speed_m_s = 0.05;         // below it with the brakes on, the car is stopped

  double wheelbase_m() const { return cg_to_front_axle_m + cg_to_rear_axle_m; }
  void validate() const;
};

// One axle's brake: torque = 2 mu_pad r_eff F_clamp; the pad friction depends on the disc
// temperature; the disc heats with the braking power and cools to ambient; the caliper follows
// the disc with a first-order lag (what the caliper's temperature sensor, and the e-caliper
// plant's thermal effects, see).
struct BrakeParams {
  double effective_radius_m = 0.12;
  double pad_mu_reference = 0.38;          // at reference temperature
  double pad_mu_reference_C = 100.0;
  double pad_mu_per_C = 1.0e-4;            // slope below the fade onset
  double fade_onset_C = 400.0;
  double fade_per_C = 4.0e-4;              // additional loss per degree above the onset
  double disc_heat_capacity_J_per_K = 3200.0;  // disc mass x specific heat
  double heat_into_disc = 0.9;             // share of the braking power that heats the disc
  double cooling_W_per_K = 8.0;            // at standstill
  double cooling_W_per_K_per_m_s = 1.2;    // growth with vehicle speed
  double caliper_time_constant_s = 120.0;  // caliper lag behind the disc
  double caliper_coupling = 0.25;          // caliper settles at ambient + coupling (disc - ambient)
  double max_clamp_force_kN = 40.0;

  double pad_mu(double disc_C) const;
  void validate(const std::string& name) const;
};

// A surface: the Magic Formula's peak scaled by mu_scale (LMUX = LMUY) and its slip stiffness by
// stiffness_scale (LKX = LKY).
struct Surface {
  std::string name;
  double mu_scale = 1.0;
  double stiffness_scale = 1.0;
};

// A rectangle of road (vehicle's start at x = 0, y = 0, heading +x) with its own surface.
struct Patch {
  double x_from_m = 0.0, x_to_m = 0.0;
  double y_from_m = -1e9, y_to_m = 1e9;
  std::size_t surface = 0;  // index into RoadParams::surfaces
};

struct RoadParams {
  std::vector<Surface> surfaces;   // the surface table (dry, wet, snow, ice, ...)
  std::size_t base_surface = 0;    // everywhere no patch covers
  std::vector<Patch> patches;      // later patches win
  double grade_percent = 0.0;      // uphill positive along x
  double ambient_C = 20.0;

  // The surface under a point; no allocation.
  const Surface& surface_at(double x_m, double y_m) const;
  void validate() const;
};

struct VehicleParams {
  TyreParams tyre;
  ChassisParams chassis;
  BrakeParams front_brake;
  BrakeParams rear_brake{0.10};
  std::vector<Surface> surfaces{{"dry", 1.0 / 1.1739, 1.0 / 1.1739}};

  const BrakeParams& brake(std::size_t wheel) const { return is_front(wheel) ? front_brake : rear_brake; }
  void validate() const;
};

}  // namespace bbw::vehicle
