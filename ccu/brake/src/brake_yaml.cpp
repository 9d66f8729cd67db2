#include "bbw/brake/brake_yaml.hpp"

#include <stdexcept>

namespace bbw::brake {

using config::Range;
using config::Reader;

BrakeControlParams read_brake_control(Reader& r) {
  BrakeControlParams p;
  p.abs_enabled = r.boolean("abs_enabled");
  {
    Reader c = r.map("car_model");
    p.car.mass_kg = c.number("mass_kg", Range::closed(100, 10000));
    p.car.cg_to_front_axle_m = c.number("cg_to_front_axle_m", Range::closed(0.3, 5));
    p.car.cg_to_rear_axle_m = c.number("cg_to_rear_axle_m", Range::closed(0.3, 5));
    p.car.cg_height_m = c.number("cg_height_m", Range::closed(0.1, 2));
    p.car.track_front_m = c.number("track_front_m", Range::closed(0.5, 3));
    p.car.track_rear_m = c.number("track_rear_m", Range::closed(0.5, 3));
    p.car.wheel_radius_m = c.number("wheel_radius_m", Range::closed(0.1, 1));
    p.car.wheel_inertia_kg_m2 = c.number("wheel_inertia_kg_m2", Range::positive());
    p.car.pad_mu = c.number("pad_mu", Range::closed(0.1, 1));
    p.car.front_effective_radius_m = c.number("front_effective_radius_m", Range::closed(0.03, 0.3));
    p.car.rear_effective_radius_m = c.number("rear_effective_radius_m", Range::closed(0.03, 0.3));
    p.car.max_clamp_force_kN = c.number("max_clamp_force_kN", Range::closed(1, 100));
    p.car.understeer_gradient_rad_s2_per_m = c.number("understeer_gradient_rad_s2_per_m", Range::closed(-0.01, 0.01));
    p.car.drag_N_s2_per_m2 = c.number("drag_N_s2_per_m2", Range::closed(0, 10));
    p.car.rolling_resistance = c.number("rolling_resistance", Range::closed(0, 0.1));
    c.finish();
  }
  {
    Reader c = r.map("mass_estimate");
    p.mass.enabled = c.boolean("enabled");
    p.mass.min_decel_g = c.number("min_decel_g", Range::closed(0.05, 1));
    p.mass.time_constant_s = c.number("time_constant_s", Range::positive());
    p.mass.max_factor = c.number("max_factor", Range::closed(1, 3));
    p.mass.deadband = c.number("deadband", Range::closed(0, 1));
    c.finish();
  }
  {
    Reader c = r.map("pedal");
    p.pedal.full_travel_mm = c.number("full_travel_mm", Range::closed(10, 300));
    p.pedal.full_force_N = c.number("full_force_N", Range::closed(50, 3000));
    p.pedal.force_exponent = c.number("force_exponent", Range::closed(1, 3));
    p.pedal.disagreement = c.number("disagreement", Range::closed(0.01, 1));
    p.pedal.dead_band = c.number("dead_band", Range{0.0, 0.5, false, true});
    p.pedal.full_demand_g = c.number("full_demand_g", Range::closed(0.1, 2));
    c.finish();
  }
  {
    Reader c = r.map("speed_estimator");
    p.speed.up_gain_per_s = c.number("up_gain_per_s", Range::positive());
    p.speed.down_gain_per_s = c.number("down_gain_per_s", Range::non_negative());
    p.speed.rolling_gain_per_s = c.number("rolling_gain_per_s", Range::positive());
    p.speed.bias_gain_per_s = c.number("bias_gain_per_s", Range::non_negative());
    p.speed.bias_max_wheel_accel_m_s2 = c.number("bias_max_wheel_accel_m_s2", Range::positive());
    p.speed.wheel_filter_s = c.number("wheel_filter_s", Range::positive());
    p.speed.free_rolling_torque_Nm = c.number("free_rolling_torque_Nm", Range::non_negative());
    p.speed.reference_release_s = c.number("reference_release_s", Range::non_negative());
    p.speed.reference_window_s = c.number("reference_window_s", Range::positive());
    p.speed.reference_tolerance_m_s = c.number("reference_tolerance_m_s", Range::positive());
    c.finish();
  }
  {
    Reader c = r.map("slip_control");
    p.slip.target_slip = c.number("target_slip", Range::closed(0.01, 0.5));
    p.slip.min_target_slip = c.number("min_target_slip", Range::closed(0.01, 0.5));
    p.slip.max_target_slip = c.number("max_target_slip", Range::closed(0.01, 0.5));
    p.slip.activation_margin = c.number("activation_margin", Range::closed(0, 0.2));
    p.slip.activation_wheel_decel_m_s2 = c.number("activation_wheel_decel_m_s2", Range::positive());
    p.slip.kp_Nm_per_rad_s = c.number("kp_Nm_per_rad_s", Range::non_negative());
    p.slip.ki_Nm_per_rad = c.number("ki_Nm_per_rad", Range::non_negative());
    p.slip.min_speed_m_s = c.number("min_speed_m_s", Range::closed(0.1, 10));
    p.slip.mu_filter_s = c.number("mu_filter_s", Range::positive());
    p.slip.dither_slip = c.number("dither_slip", Range::closed(0, 0.1));
    p.slip.dither_half_period_s = c.number("dither_half_period_s", Range::positive());
    p.slip.dither_settle_s = c.number("dither_settle_s", Range::non_negative());
    p.slip.search_step = c.number("search_step", Range::closed(0, 0.1));
    p.slip.search_threshold_mu = c.number("search_threshold_mu", Range::non_negative());
    p.slip.jump_wheel_decel_m_s2 = c.number("jump_wheel_decel_m_s2", Range::positive());
    p.slip.jump_slip_margin = c.number("jump_slip_margin", Range::closed(0, 0.5));
    p.slip.jump_hard_decel_m_s2 = c.number("jump_hard_decel_m_s2", Range::non_negative());
    p.slip.jump_release_factor = c.number("jump_release_factor", Range::closed(0, 1));
    p.slip.active_min_clamp_kN = c.number("active_min_clamp_kN", Range::closed(0, 5));
    p.slip.caliper_model = c.boolean("caliper_model");
    p.slip.caliper_release_kN = c.number("caliper_release_kN", Range::closed(0, 5));
    p.slip.caliper_gap_s = c.number("caliper_gap_s", Range::closed(0.001, 1));
    p.slip.caliper_retract_s = c.number("caliper_retract_s", Range::closed(0.001, 1));
    p.slip.caliper_rate_kN_s = c.number("caliper_rate_kN_s", Range::positive());
    p.slip.caliper_lag_s = c.number("caliper_lag_s", Range::closed(0.001, 1));
    p.slip.release_freeze_margin_Nm = c.number("release_freeze_margin_Nm", Range::closed(0, 1000));
    c.finish();
  }
  {
    Reader c = r.map("yaw_limit");
    p.yaw.enabled = c.boolean("enabled");
    p.yaw.asymmetry_ratio = c.number("asymmetry_ratio", Range{0.0, 1.0, true, true});
    p.yaw.min_difference_Nm = c.number("min_difference_Nm", Range::non_negative());
    p.yaw.min_mu_difference = c.number("min_mu_difference", Range::closed(0, 1));
    p.yaw.ramp_Nm_per_s = c.number("ramp_Nm_per_s", Range::positive());
    p.yaw.initial_Nm = c.number("initial_Nm", Range::non_negative());
    p.yaw.yaw_error_gain_Nm_per_rad_s = c.number("yaw_error_gain_Nm_per_rad_s", Range::non_negative());
    p.yaw.heading_error_gain_Nm_per_rad = c.number("heading_error_gain_Nm_per_rad", Range::non_negative());
    p.yaw.counter_steer_gain_Nm_per_rad = c.number("counter_steer_gain_Nm_per_rad", Range::non_negative());
    p.yaw.max_ramp_Nm = c.number("max_ramp_Nm", Range::non_negative());
    p.yaw.pre_split_ramp_Nm_per_s = c.number("pre_split_ramp_Nm_per_s", Range::non_negative());
    p.yaw.latch_driver_yaw_rate = c.boolean("latch_driver_yaw_rate");
    p.yaw.rear_select_low = c.boolean("rear_select_low");
    p.yaw.low_side_capacity_share = c.number("low_side_capacity_share", Range::closed(0, 1));
    p.yaw.redistribute_lost_corner = c.boolean("redistribute_lost_corner");
    p.yaw.lost_corner_initial_Nm = c.number("lost_corner_initial_Nm", Range::non_negative());
    p.yaw.lost_corner_ramp_Nm_per_s = c.number("lost_corner_ramp_Nm_per_s", Range::positive());
    c.finish();
  }
  r.finish();
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    r.fail("", e.what());
  }
  return p;
}

BrakeControlParams load_brake_control(const std::string& file) {
  Reader r = Reader::from_file(file);
  return read_brake_control(r);
}

}  // namespace bbw::brake
