#include "bbw/vehicle/params.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace bbw::vehicle {

namespace {

[[noreturn]] void bad(const std::string& field, double value, const char* rule) {
  std::ostringstream os;
  os << field << " = " << value << ": " << rule;
  throw std::invalid_argument(os.str());
}
void positive(const std::string& field, double v) {
  if (!(std::isfinite(v) && v > 0.0)) bad(field, v, "must be > 0");
}
void non_negative(const std::string& field, double v) {
  if (!(std::isfinite(v) && v >= 0.0)) bad(field, v, "must be >= 0");
}
void finite(const std::string& field, double v) {
  if (!std::isfinite(v)) bad(field, v, "must be finite");
}
void in_range(const std::string& field, double v, double lo, double hi) {
  if (!(std::isfinite(v) && v >= lo && v <= hi)) {
    std::ostringstream rule;
    rule << "must be in [" << lo << ", " << hi << "]";
    bad(field, v, rule.str().c_str());
  }
}

}  // namespace

void TyreParams::validate() const {
  positive("tyre.nominal_load_N", nominal_load_N);
  in_range("tyre.pcx1", pcx1, 1.0, 2.0);
  in_range("tyre.pdx1", pdx1, 0.1, 3.0);
  in_range("tyre.pdx2", pdx2, -1.0, 1.0);
  in_range("tyre.pex1", pex1, -10.0, 1.0);
  finite("tyre.pex2", pex2);
  finite("tyre.pex3", pex3);
  positive("tyre.pkx1", pkx1);
  finite("tyre.pkx2", pkx2);
  finite("tyre.pkx3", pkx3);
  in_range("tyre.pcy1", pcy1, 1.0, 2.0);
  in_range("tyre.pdy1", pdy1, 0.1, 3.0);
  in_range("tyre.pdy2", pdy2, -1.0, 1.0);
  in_range("tyre.pey1", pey1, -10.0, 1.0);
  positive("tyre.pky1 (magnitude; the file's sign convention is ISO, negative)", pky1);
  positive("tyre.pky2", pky2);
  positive("tyre.rbx1", rbx1);
  finite("tyre.rbx2", rbx2);
  positive("tyre.rcx1", rcx1);
  in_range("tyre.rex1", rex1, -10.0, 1.0);
  positive("tyre.rby1", rby1);
  finite("tyre.rby2", rby2);
  positive("tyre.rcy1", rcy1);
  in_range("tyre.rey1", rey1, -10.0, 1.0);
}

void ChassisParams::validate() const {
  positive("chassis.mass_kg", mass_kg);
  positive("chassis.yaw_inertia_kg_m2", yaw_inertia_kg_m2);
  positive("chassis.cg_to_front_axle_m", cg_to_front_axle_m);
  positive("chassis.cg_to_rear_axle_m", cg_to_rear_axle_m);
  positive("chassis.track_front_m", track_front_m);
  positive("chassis.track_rear_m", track_rear_m);
  positive("chassis.cg_height_m", cg_height_m);
  in_range("chassis.front_roll_share", front_roll_share, 0.0, 1.0);
  positive("chassis.wheel_radius_m", wheel_radius_m);
  positive("chassis.wheel_inertia_kg_m2", wheel_inertia_kg_m2);
  non_negative("chassis.drag_coefficient", drag_coefficient);
  non_negative("chassis.frontal_area_m2", frontal_area_m2);
  non_negative("chassis.air_density_kg_m3", air_density_kg_m3);
  in_range("chassis.rolling_resistance", rolling_resistance, 0.0, 0.1);
  positive("chassis.slip_speed_floor_m_s", slip_speed_floor_m_s);
  positive("chassis.stop_speed_m_s", stop_speed_m_s);
}

double BrakeParams::pad_mu(double disc_C) const {
  double mu = pad_mu_reference + pad_mu_per_C * (disc_C - pad_mu_reference_C);
  if (disc_C > fade_onset_C) mu -= fade_per_C * (disc_C - fade_onset_C);
  return std::max(0.05, mu);
}

void BrakeParams::validate(const std::string& name) const {
  positive(name + ".effective_radius_m", effective_radius_m);
  in_range(name + ".pad_mu_reference", pad_mu_reference, 0.1, 1.0);
  finite(name + ".pad_mu_reference_C", pad_mu_reference_C);
  in_range(name + ".pad_mu_per_C", pad_mu_per_C, -0.01, 0.01);
  finite(name + ".fade_onset_C", fade_onset_C);
  in_range(name + ".fade_per_C", fade_per_C, 0.0, 0.01);
  positive(name + ".disc_heat_capacity_J_per_K", disc_heat_capacity_J_per_K);
  in_range(name + ".heat_into_disc", heat_into_disc, 0.0, 1.0);
  non_negative(name + ".cooling_W_per_K", cooling_W_per_K);
  non_negative(name + ".cooling_W_per_K_per_m_s", cooling_W_per_K_per_m_s);
  positive(name + ".caliper_time_constant_s", caliper_time_constant_s);
  in_range(name + ".caliper_coupling", caliper_coupling, 0.0, 1.0);
  positive(name + ".max_clamp_force_kN", max_clamp_force_kN);
}

const Surface& RoadParams::surface_at(double x_m, double y_m) const {
  std::size_t s = base_surface;
  for (const Patch& p : patches) {
    if (x_m >= p.x_from_m && x_m < p.x_to_m && y_m >= p.y_from_m && y_m < p.y_to_m) s = p.surface;
  }
  return surfaces[s];
}

void RoadParams::validate() const {
  if (surfaces.empty()) throw std::invalid_argument("road: no surfaces");
  for (const Surface& s : surfaces) {
    in_range("surface " + s.name + ".mu_scale", s.mu_scale, 0.01, 2.0);
    in_range("surface " + s.name + ".stiffness_scale", s.stiffness_scale, 0.01, 2.0);
  }
  if (base_surface >= surfaces.size()) throw std::invalid_argument("road: base surface out of range");
  for (const Patch& p : patches) {
    if (p.surface >= surfaces.size()) throw std::invalid_argument("road: patch surface out of range");
    if (!(p.x_to_m > p.x_from_m) || !(p.y_to_m > p.y_from_m)) {
      throw std::invalid_argument("road: a patch must have x_to_m > x_from_m and y_to_m > y_from_m");
    }
  }
  in_range("road.grade_percent", grade_percent, -30.0, 30.0);
  in_range("road.ambient_C", ambient_C, -40.0, 50.0);
}

void VehicleParams::validate() const {
  tyre.validate();
  chassis.validate();
  front_brake.validate("front_brake");
  rear_brake.validate("rear_brake");
  if (surfaces.empty()) throw std::invalid_argument("surfaces: at least one surface is needed");
}

}  // namespace bbw::vehicle
