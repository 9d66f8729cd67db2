#include "bbw/vehicle/vehicle.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bbw::vehicle {

namespace {
constexpr double kG = 9.81;
}

Vehicle::Vehicle(const VehicleParams& params, const RoadParams& road) : p_(params), road_(road) {
  p_.validate();
  road_.validate();
  reset(0.0, {20, 20, 20, 20}, {20, 20, 20, 20});
}

double Vehicle::wheel_x_m(std::size_t w) const {
  return is_front(w) ? p_.chassis.cg_to_front_axle_m : -p_.chassis.cg_to_rear_axle_m;
}
double Vehicle::wheel_y_m(std::size_t w) const {
  const double t = is_front(w) ? p_.chassis.track_front_m : p_.chassis.track_rear_m;
  return is_left(w) ? 0.5 * t : -0.5 * t;
}

double Vehicle::static_load_N(std::size_t w) const {
  const ChassisParams& c = p_.chassis;
  const double axle = is_front(w) ? c.cg_to_rear_axle_m : c.cg_to_front_axle_m;
  return 0.5 * c.mass_kg * kG * axle / c.wheelbase_m();
}

void Vehicle::reset(double speed_m_s, const std::array<double, kWheels>& disc_C, const std::array<double, kWheels>& caliper_C) {
  s_ = VehicleState{};
  s_.vx_m_s = speed_m_s;
  for (std::size_t w = 0; w < kWheels; ++w) {
    s_.wheels[w].spin_rad_s = speed_m_s / p_.chassis.wheel_radius_m;
    s_.wheels[w].disc_C = disc_C[w];
    s_.wheels[w].caliper_C = caliper_C[w];
  }
  out_ = {};
  for (std::size_t w = 0; w < kWheels; ++w) out_[w].load_N = static_load_N(w);
}

// Quasi-static load transfer from the last step's body accelerations (pitch and roll are not
// states: the loads follow the accelerations at once).
void Vehicle::loads(double grade_cos, std::array<double, kWheels>& fz) const {
  const ChassisParams& c = p_.chassis;
  const double L = c.wheelbase_m();
  const double m = c.mass_kg;
  const double front_axle = m * (kG * grade_cos * c.cg_to_rear_axle_m - s_.ax_m_s2 * c.cg_height_m) / L;
  const double rear_axle = m * (kG * grade_cos * c.cg_to_front_axle_m + s_.ax_m_s2 * c.cg_height_m) / L;
  const double lateral_total = m * s_.ay_m_s2 * c.cg_height_m;  // roll moment, N m
  const double df = c.front_roll_share * lateral_total / c.track_front_m;
  const double dr = (1.0 - c.front_roll_share) * lateral_total / c.track_rear_m;
  // ay > 0 (to the left, a left turn) loads the right wheels.
  fz[0] = std::max(0.0, 0.5 * front_axle - df);
  fz[1] = std::max(0.0, 0.5 * front_axle + df);
  fz[2] = std::max(0.0, 0.5 * rear_axle - dr);
  fz[3] = std::max(0.0, 0.5 * rear_axle + dr);
}

const VehicleState& Vehicle::step(double dt_s, const VehicleInputs& in) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw std::invalid_argument("Vehicle::step: dt_s must be > 0");
  const ChassisParams& c = p_.chassis;
  const double R = c.wheel_radius_m;
  const double grade = std::atan(road_.grade_percent / 100.0);
  std::array<double, kWheels> fz{};
  loads(std::cos(grade), fz);

  const bool braking_any = std::any_of(in.clamp_force_kN.begin(), in.clamp_force_kN.end(), [](double f) { return f > 0.0; });
  const bool driving_any = std::any_of(in.drive_torque_Nm.begin(), in.drive_torque_Nm.end(), [](double t) { return t > 0.0; });
  if (s_.stopped && driving_any) s_.stopped = false;

  // Earth position of the CG and heading, for the road lookup.
  const double cy = std::cos(s_.yaw_rad), sy = std::sin(s_.yaw_rad);
  double fx_body = 0.0, fy_body = 0.0, mz = 0.0;
  for (std::size_t w = 0; w < kWheels; ++w) {
    WheelState& ws = s_.wheels[w];
    WheelOutput& o = out_[w];
    const BrakeParams& b = p_.brake(w);
    const double xw = wheel_x_m(w), yw = wheel_y_m(w);
    const Surface& surf = road_.surface_at(s_.x_m + cy * xw - sy * yw, s_.y_m + sy * xw + cy * yw);
    // Contact patch velocity in the wheel frame.
    const double vxb = s_.vx_m_s - s_.yaw_rate_rad_s * yw;
    const double vyb = s_.vy_m_s + s_.yaw_rate_rad_s * xw;
    const double delta = is_front(w) ? in.steer_rad : 0.0;
    const double cd = std::cos(delta), sd = std::sin(delta);
    const double vxw = cd * vxb + sd * vyb;
    const double vyw = -sd * vxb + cd * vyb;
    const double vden = std::max(std::abs(vxw), c.slip_speed_floor_m_s);
    const double brake_Nm = 2.0 * b.pad_mu(ws.disc_C) * b.effective_radius_m * std::max(0.0, in.clamp_force_kN[w]) * 1000.0;
    double kappa = (R * ws.spin_rad_s - vxw) / vden;
    const double alpha = std::atan2(vyw, vden);
    TyreForce f = tyre_force(p_.tyre, fz[w], kappa, alpha, surf.mu_scale, surf.stiffness_scale);
    // Wheel spin, linearly implicit in the tyre force (stable at any speed): I dw/dt =
    // T_drive - R Fx(w) - T_brake, the brake a Coulomb friction that cannot turn the wheel back.
    const double I = c.wheel_inertia_kg_m2;
    const double drive = in.drive_torque_Nm[w];
    const double rolling_Nm = c.rolling_resistance * fz[w] * R * (ws.spin_rad_s > 0.0 ? 1.0 : 0.0);
    const double free_Nm = drive - R * f.longitudinal_N - rolling_Nm;
    double w_new = 0.0;
    if (ws.spin_rad_s <= 0.0 && std::abs(free_Nm) <= brake_Nm) {
      w_new = 0.0;  // held by the brake
    } else {
      const double net = free_Nm - brake_Nm;
      const double dnet_dw = -R * std::max(0.0, f.dFx_dkappa_N) * R / vden;
      w_new = ws.spin_rad_s + dt_s * (net / I) / (1.0 - dt_s * dnet_dw / I);
      w_new = std::max(0.0, w_new);
    }
    ws.angle_rad += 0.5 * (ws.spin_rad_s + w_new) * dt_s;
    ws.spin_rad_s = s_.stopped ? 0.0 : w_new;
    // The force at the new spin (consistent with the implicit step).
    kappa = (R * ws.spin_rad_s - vxw) / vden;
    f = tyre_force(p_.tyre, fz[w], kappa, alpha, surf.mu_scale, surf.stiffness_scale);
    if (s_.stopped) f = {};
    // Brake heat: the power the pads dissipate (torque x wheel speed).
    const double power_W = brake_Nm * ws.spin_rad_s;
    const double cooling = b.cooling_W_per_K + b.cooling_W_per_K_per_m_s * std::abs(s_.vx_m_s);
    ws.disc_C += dt_s * (b.heat_into_disc * power_W - cooling * (ws.disc_C - road_.ambient_C)) / b.disc_heat_capacity_J_per_K;
    const double caliper_target = road_.ambient_C + b.caliper_coupling * (ws.disc_C - road_.ambient_C);
    ws.caliper_C += dt_s * (caliper_target - ws.caliper_C) / b.caliper_time_constant_s;
    // Into the body frame.
    const double fxb = cd * f.longitudinal_N - sd * f.lateral_N;
    const double fyb = sd * f.longitudinal_N + cd * f.lateral_N;
    fx_body += fxb;
    fy_body += fyb;
    mz += xw * fyb - yw * fxb;
    o.load_N = fz[w];
    o.slip = kappa;
    o.slip_angle_rad = alpha;
    o.longitudinal_N = f.longitudinal_N;
    o.lateral_N = f.lateral_N;
    o.mu_used = fz[w] > 0.0 ? std::hypot(f.longitudinal_N, f.lateral_N) / fz[w] : 0.0;
    o.surface_mu_scale = surf.mu_scale;
    o.brake_torque_Nm = brake_Nm;
    o.ground_speed_m_s = vxw;
  }
  if (s_.stopped) {
    s_.time_s += dt_s;
    s_.ax_m_s2 = s_.ay_m_s2 = 0.0;
    return s_;
  }
  const double m = c.mass_kg;
  const double v = s_.vx_m_s;
  const double drag_N = 0.5 * c.air_density_kg_m3 * c.drag_coefficient * c.frontal_area_m2 * v * std::abs(v);
  const double grade_N = m * kG * std::sin(grade);
  const double ax = (fx_body - drag_N - grade_N) / m;  // body-frame force / mass
  const double ay = fy_body / m;
  const double vx_dot = ax + s_.yaw_rate_rad_s * s_.vy_m_s;
  const double vy_dot = ay - s_.yaw_rate_rad_s * s_.vx_m_s;
  const double r_dot = mz / c.yaw_inertia_kg_m2;
  s_.vx_m_s += dt_s * vx_dot;
  s_.vy_m_s += dt_s * vy_dot;
  s_.yaw_rate_rad_s += dt_s * r_dot;
  s_.ax_m_s2 = ax;
  s_.ay_m_s2 = ay;
  const double yaw_mid = s_.yaw_rad + 0.5 * dt_s * s_.yaw_rate_rad_s;
  const double cm = std::cos(yaw_mid), sm = std::sin(yaw_mid);
  const double dx = dt_s * (cm * s_.vx_m_s - sm * s_.vy_m_s);
  const double dy = dt_s * (sm * s_.vx_m_s + cm * s_.vy_m_s);
  s_.x_m += dx;
  s_.y_m += dy;
  s_.path_m += std::hypot(dx, dy);
  s_.yaw_rad += dt_s * s_.yaw_rate_rad_s;
  s_.time_s += dt_s;
  if (braking_any && !driving_any && std::hypot(s_.vx_m_s, s_.vy_m_s) <= c.stop_speed_m_s) {
    s_.stopped = true;
    s_.vx_m_s = s_.vy_m_s = s_.yaw_rate_rad_s = 0.0;
    for (WheelState& ws : s_.wheels) ws.spin_rad_s = 0.0;
  }
  return s_;
}

}  // namespace bbw::vehicle
