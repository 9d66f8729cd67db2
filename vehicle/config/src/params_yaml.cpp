#include "bbw/vehicle/params_yaml.hpp"

#include <stdexcept>

namespace bbw::vehicle {

using config::Range;
using config::Reader;

namespace {

template <typename F>
void checked(const Reader& r, F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    r.fail("", e.what());
  }
}

BrakeParams read_brake(Reader b) {
  BrakeParams p;
  p.effective_radius_m = b.number("effective_radius_m", Range::closed(0.03, 0.3));
  p.pad_mu_reference = b.number("pad_mu_reference", Range::closed(0.1, 1.0));
  p.pad_mu_reference_C = b.number("pad_mu_reference_C", Range::closed(-40, 800));
  p.pad_mu_per_C = b.number("pad_mu_per_C", Range::closed(-0.01, 0.01));
  p.fade_onset_C = b.number("fade_onset_C", Range::closed(0, 1000));
  p.fade_per_C = b.number("fade_per_C", Range::closed(0, 0.01));
  p.disc_heat_capacity_J_per_K = b.number("disc_heat_capacity_J_per_K", Range::positive());
  p.heat_into_disc = b.number("heat_into_disc", Range::closed(0, 1));
  p.cooling_W_per_K = b.number("cooling_W_per_K", Range::non_negative());
  p.cooling_W_per_K_per_m_s = b.number("cooling_W_per_K_per_m_s", Range::non_negative());
  p.caliper_time_constant_s = b.number("caliper_time_constant_s", Range::positive());
  p.caliper_coupling = b.number("caliper_coupling", Range::closed(0, 1));
  p.max_clamp_force_kN = b.number("max_clamp_force_kN", Range::closed(1, 100));
  b.finish();
  return p;
}

}  // namespace

VehicleConfig read_vehicle_config(Reader& r) {
  VehicleConfig c;
  {
    Reader t = r.map("tyre");
    TyreParams& p = c.vehicle.tyre;
    p.nominal_load_N = t.number("FNOMIN_N", Range::positive());
    p.pcx1 = t.number("PCX1", Range::closed(1.0, 2.0));
    p.pdx1 = t.number("PDX1", Range::closed(0.1, 3.0));
    p.pdx2 = t.number("PDX2", Range::closed(-1.0, 1.0));
    p.pex1 = t.number("PEX1", Range::closed(-10.0, 1.0));
    p.pex2 = t.number("PEX2");
    p.pex3 = t.number("PEX3");
    p.pkx1 = t.number("PKX1", Range::positive());
    p.pkx2 = t.number("PKX2");
    p.pkx3 = t.number("PKX3");
    p.pcy1 = t.number("PCY1", Range::closed(1.0, 2.0));
    p.pdy1 = t.number("PDY1", Range::closed(0.1, 3.0));
    p.pdy2 = t.number("PDY2", Range::closed(-1.0, 1.0));
    p.pey1 = t.number("PEY1", Range::closed(-10.0, 1.0));
    // The file keeps the ISO sign (negative); the model uses the magnitude.
    p.pky1 = -t.number("PKY1", Range{-1e9, 0.0, false, true});
    p.pky2 = t.number("PKY2", Range::positive());
    p.rbx1 = t.number("RBX1", Range::positive());
    p.rbx2 = t.number("RBX2");
    p.rcx1 = t.number("RCX1", Range::positive());
    p.rex1 = t.number("REX1", Range::closed(-10.0, 1.0));
    p.rby1 = t.number("RBY1", Range::positive());
    p.rby2 = t.number("RBY2");
    p.rcy1 = t.number("RCY1", Range::positive());
    p.rey1 = t.number("REY1", Range::closed(-10.0, 1.0));
    t.finish();
  }
  {
    Reader h = r.map("chassis");
    ChassisParams& p = c.vehicle.chassis;
    p.mass_kg = h.number("mass_kg", Range::closed(100, 10000));
    p.yaw_inertia_kg_m2 = h.number("yaw_inertia_kg_m2", Range::positive());
    p.cg_to_front_axle_m = h.number("cg_to_front_axle_m", Range::closed(0.3, 5));
    p.cg_to_rear_axle_m = h.number("cg_to_rear_axle_m", Range::closed(0.3, 5));
    p.track_front_m = h.number("track_front_m", Range::closed(0.5, 3));
    p.track_rear_m = h.number("track_rear_m", Range::closed(0.5, 3));
    p.cg_height_m = h.number("cg_height_m", Range::closed(0.1, 2));
    p.front_roll_share = h.number("front_roll_share", Range::closed(0, 1));
    p.wheel_radius_m = h.number("wheel_radius_m", Range::closed(0.1, 1));
    p.wheel_inertia_kg_m2 = h.number("wheel_inertia_kg_m2", Range::positive());
    p.drag_coefficient = h.number("drag_coefficient", Range::closed(0, 2));
    p.frontal_area_m2 = h.number("frontal_area_m2", Range::closed(0, 10));
    p.air_density_kg_m3 = h.number("air_density_kg_m3", Range::closed(0, 2));
    p.rolling_resistance = h.number("rolling_resistance", Range::closed(0, 0.1));
    p.slip_speed_floor_m_s = h.number("slip_speed_floor_m_s", Range::closed(0.1, 5));
    p.stop_speed_m_s = h.number("stop_speed_m_s", Range::closed(0.001, 1));
    h.finish();
  }
  c.vehicle.front_brake = read_brake(r.map("front_brake"));
  c.vehicle.rear_brake = read_brake(r.map("rear_brake"));
  c.vehicle.surfaces.clear();
  for (Reader s : r.maps("surfaces")) {
    Surface surf;
    surf.name = s.string("name");
    surf.mu_scale = s.number("mu_scale", Range::closed(0.01, 2.0));
    surf.stiffness_scale = s.number("stiffness_scale", Range::closed(0.01, 2.0));
    for (const Surface& o : c.vehicle.surfaces) {
      if (o.name == surf.name) s.fail("name", "surface '" + surf.name + "' is defined twice");
    }
    s.finish();
    c.vehicle.surfaces.push_back(surf);
  }
  if (c.vehicle.surfaces.empty()) r.fail("surfaces", "at least one surface is needed");
  {
    Reader w = r.map("wheel_speed_sensor");
    c.wheel_speed.teeth = static_cast<int>(w.integer("teeth", 4, 256));
    c.wheel_speed.timer_resolution_s = w.number("timer_resolution_s", Range{0.0, 1e-3, true, false});
    c.wheel_speed.pitch_error = w.number("pitch_error", Range::closed(0, 0.05));
    c.wheel_speed.timeout_s = w.number("timeout_s", Range::closed(0.005, 5));
    w.finish();
  }
  {
    Reader i = r.map("imu");
    c.imu.accel_noise_m_s2 = i.number("accel_noise_m_s2", Range::closed(0, 5));
    c.imu.accel_bias_m_s2 = i.number("accel_bias_m_s2", Range::closed(-2, 2));
    c.imu.yaw_rate_noise_rad_s = i.number("yaw_rate_noise_rad_s", Range::closed(0, 1));
    c.imu.yaw_rate_bias_rad_s = i.number("yaw_rate_bias_rad_s", Range::closed(-0.5, 0.5));
    i.finish();
  }
  {
    Reader p = r.map("pedal");
    c.pedal.full_travel_mm = p.number("full_travel_mm", Range::closed(10, 300));
    c.pedal.full_force_N = p.number("full_force_N", Range::closed(50, 3000));
    c.pedal.force_exponent = p.number("force_exponent", Range::closed(1, 3));
    c.pedal.travel_noise_mm = p.number("travel_noise_mm", Range::closed(0, 10));
    c.pedal.force_noise_N = p.number("force_noise_N", Range::closed(0, 100));
    p.finish();
  }
  r.finish();
  checked(r, [&] { c.vehicle.validate(); });
  return c;
}

VehicleConfig load_vehicle_config(const std::string& file) {
  Reader r = Reader::from_file(file);
  return read_vehicle_config(r);
}

}  // namespace bbw::vehicle
