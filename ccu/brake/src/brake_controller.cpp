#include "bbw/brake/brake_controller.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bbw::brake {

namespace {
constexpr double kG = 9.81;

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(what);
}
}  // namespace

void BrakeControlParams::validate() const {
  require(car.mass_kg > 0 && car.cg_to_front_axle_m > 0 && car.cg_to_rear_axle_m > 0 && car.cg_height_m > 0 &&
              car.track_front_m > 0 && car.track_rear_m > 0 && car.wheel_radius_m > 0 && car.wheel_inertia_kg_m2 > 0 &&
              car.pad_mu > 0 && car.front_effective_radius_m > 0 && car.rear_effective_radius_m > 0 &&
              car.max_clamp_force_kN > 0,
          "car: every value must be > 0");
  require(pedal.full_travel_mm > 0 && pedal.full_force_N > 0 && pedal.force_exponent >= 1 && pedal.disagreement > 0 &&
              pedal.dead_band >= 0 && pedal.dead_band < 0.5 && pedal.full_demand_g > 0,
          "pedal: full travel, force, disagreement, full_demand_g > 0; exponent >= 1; dead_band in [0, 0.5)");
  require(slip.min_target_slip > 0 && slip.min_target_slip <= slip.target_slip && slip.target_slip <= slip.max_target_slip &&
              slip.max_target_slip < 0.5,
          "slip: 0 < min_target_slip <= target_slip <= max_target_slip < 0.5");
  require(slip.kp_Nm_per_rad_s >= 0 && slip.ki_Nm_per_rad >= 0 && slip.min_speed_m_s > 0 && slip.mu_filter_s > 0 &&
              slip.dither_slip >= 0 && slip.dither_half_period_s > slip.dither_settle_s && slip.search_step >= 0,
          "slip: gains >= 0, min_speed_m_s and mu_filter_s > 0, dither_half_period_s > dither_settle_s");
  require(yaw.asymmetry_ratio > 0 && yaw.asymmetry_ratio < 1 && yaw.ramp_Nm_per_s > 0 && yaw.initial_Nm >= 0,
          "yaw: asymmetry_ratio in (0, 1), ramp_Nm_per_s > 0, initial_Nm >= 0");
  require(speed.up_gain_per_s > 0 && speed.down_gain_per_s >= 0 && speed.rolling_gain_per_s > 0 && speed.bias_gain_per_s >= 0 &&
              speed.bias_max_wheel_accel_m_s2 > 0 && speed.wheel_filter_s > 0 && speed.reference_release_s >= 0 &&
              speed.reference_window_s > 0 && speed.reference_tolerance_m_s > 0,
          "speed: gains must be >= 0 (up and rolling > 0); filter, reference window and tolerance > 0");
  require(slip.caliper_release_kN >= 0 && slip.caliper_gap_s > 0 && slip.caliper_retract_s > 0 && slip.caliper_rate_kN_s > 0 &&
              slip.caliper_lag_s > 0 && slip.release_freeze_margin_Nm >= 0,
          "slip: caliper_release_kN, release_freeze_margin_Nm >= 0; caliper_gap_s, caliper_retract_s, caliper_rate_kN_s, caliper_lag_s > 0");
  require(car.drag_N_s2_per_m2 >= 0 && car.rolling_resistance >= 0 && mass.min_decel_g > 0 && mass.time_constant_s > 0 &&
              mass.max_factor >= 1 && mass.deadband >= 0,
          "car: drag and rolling resistance >= 0; mass_estimate: min_decel_g, time_constant_s > 0, max_factor >= 1, deadband >= 0");
}

PedalDemand pedal_demand(const PedalDemandParams& p, double travel_mm, double force_N) {
  const double by_travel = std::clamp(travel_mm / p.full_travel_mm, 0.0, 1.0);
  const double by_force = std::pow(std::clamp(force_N / p.full_force_N, 0.0, 1.0), 1.0 / p.force_exponent);
  PedalDemand d;
  d.sensors_disagree = std::abs(by_travel - by_force) > p.disagreement;
  // Agreeing: their mean; disagreeing: the larger (a failed sensor must not take the brake away).
  double v = d.sensors_disagree ? std::max(by_travel, by_force) : 0.5 * (by_travel + by_force);
  v = v < p.dead_band ? 0.0 : (v - p.dead_band) / (1.0 - p.dead_band);
  d.demand = v;
  return d;
}

BrakeController::BrakeController(const BrakeControlParams& p)
    : p_(p),
      speed_(p.speed, p.car.wheel_radius_m),
      slip_{SlipController(p.slip, p.car.wheel_radius_m, p.car.wheel_inertia_kg_m2, 2000.0 * p.car.pad_mu * p.car.front_effective_radius_m),
            SlipController(p.slip, p.car.wheel_radius_m, p.car.wheel_inertia_kg_m2, 2000.0 * p.car.pad_mu * p.car.front_effective_radius_m),
            SlipController(p.slip, p.car.wheel_radius_m, p.car.wheel_inertia_kg_m2, 2000.0 * p.car.pad_mu * p.car.rear_effective_radius_m),
            SlipController(p.slip, p.car.wheel_radius_m, p.car.wheel_inertia_kg_m2, 2000.0 * p.car.pad_mu * p.car.rear_effective_radius_m)},
      mass_kg_(p.car.mass_kg) {
  p_.validate();
}

double BrakeController::mass_used_kg() const {
  return std::max(p_.car.mass_kg, mass_kg_ - p_.mass.deadband * p_.car.mass_kg);
}

double BrakeController::clamp_kN(std::size_t w, double torque) const {
  const double r = w < 2 ? p_.car.front_effective_radius_m : p_.car.rear_effective_radius_m;
  return std::clamp(torque / (2.0 * p_.car.pad_mu * r) / 1000.0, 0.0, p_.car.max_clamp_force_kN);
}

double BrakeController::torque_Nm(std::size_t w, double clamp) const {
  const double r = w < 2 ? p_.car.front_effective_radius_m : p_.car.rear_effective_radius_m;
  return 2.0 * p_.car.pad_mu * r * clamp * 1000.0;
}

std::size_t BrakeController::lost_corner(const BrakeMeasurements& m) {
  std::size_t lost = 4, n = 0;
  for (std::size_t w = 0; w < 4; ++w) {
    if (!m.available[w]) {
      lost = w;
      ++n;
    }
  }
  return n == 1 ? lost : 4;  // two or more lost: no redistribution (the yaw limitation alone)
}

const BrakeOutput& BrakeController::update(double dt_s, const BrakeMeasurements& m) {
  const CarModel& c = p_.car;
  const PedalDemand pd = pedal_demand(p_.pedal, m.pedal_travel_mm, m.pedal_force_N);
  if (pd.sensors_disagree) ++out_.pedal_disagreements;
  out_.demand = pd.demand;
  const double z_request = out_.demand * p_.pedal.full_demand_g;
  out_.decel_request_g = z_request;
  bool any_active = false;
  double held_slip = 1.0;
  for (const SlipController& s : slip_) {
    any_active = any_active || s.last().active;
    if (s.last().active) held_slip = std::min(held_slip, s.target_slip());
  }
  if (!any_active) held_slip = 0.0;
  // The estimate follows the fastest wheel up; down only a wheel that rolls freely (its command
  // at most the free-rolling torque long enough), never one under slip control (held at a slip of
  // the estimate itself).
  std::array<WheelBrakeStatus, 4> status{};
  for (std::size_t i = 0; i < 4; ++i) {
    // The pads are off once the command is at most the free-rolling torque and (with the caliper
    // model) the model's force has reached 0 and its air gap has opened: a small command still
    // leaves a force that holds an ice wheel at a steady slip, which is no free rolling.
    const bool off = out_.torque_Nm[i] <= p_.speed.free_rolling_torque_Nm && (!p_.slip.caliper_model || slip_[i].model_gap() >= 1.0);
    pads_off_s_[i] = off ? pads_off_s_[i] + dt_s : 0.0;
    status[i].pads_off_s = pads_off_s_[i];
    status[i].controlled = slip_[i].last().active;
  }
  const double v = speed_.update(dt_s, m.wheel_rad_s, m.ax_m_s2, any_active || z_request > 0.3, held_slip, status);
  out_.speed_estimate_m_s = v;
  // Load transfer at the measured deceleration (never more than requested).
  ax_filt_ += std::min(1.0, dt_s / 0.03) * (m.ax_m_s2 - ax_filt_);
  const double z_meas = std::clamp(-ax_filt_ / kG, 0.0, z_request);
  const double L = c.cg_to_front_axle_m + c.cg_to_rear_axle_m;
  // The car's mass from its own braking (a laden car): while no wheel is under slip control (the
  // tyres carry what the brakes apply), the tyres' braking forces (the slip controllers' last
  // R Fx = T + I dw/dt, through the loads they were given) and the driving resistance over the
  // measured deceleration.
  // The tyres' forces below are the slip controllers' of the last period, made from the clamp-force
  // estimates they had then, themselves a period old (the corners' last samples): the deceleration
  // they are divided by is the one of two periods ago. Divided by the present one, the apply ramp
  // (where the estimate runs before slip control takes the wheels) read a car of 1393 kg as 1299.
  ax_mass_filt_ += std::min(1.0, dt_s / 0.03) * (ax_past_m_s2_[1] - ax_mass_filt_);
  ax_past_m_s2_[1] = ax_past_m_s2_[0];
  ax_past_m_s2_[0] = m.ax_m_s2;
  if (p_.mass.enabled && !any_active && z_request > 0.0 && -ax_filt_ > p_.mass.min_decel_g * kG && v > p_.slip.min_speed_m_s) {
    double fx_N = 0.0;
    for (std::size_t w = 0; w < 4; ++w) fx_N += m.available[w] ? slip_[w].last().mu_estimate * load_in_N_[w] : 0.0;
    const double resistance_N = c.drag_N_s2_per_m2 * v * v + c.rolling_resistance * mass_kg_ * kG;
    const double raw_kg = std::clamp((fx_N + resistance_N) / -std::min(ax_mass_filt_, -1e-3), c.mass_kg, p_.mass.max_factor * c.mass_kg);
    mass_kg_ += std::min(1.0, dt_s / p_.mass.time_constant_s) * (raw_kg - mass_kg_);
  }
  const double mass = mass_used_kg();
  const double total_N = mass * kG * z_request;
  const double front_share = std::clamp((c.cg_to_rear_axle_m + c.cg_height_m * z_meas) / L, 0.3, 0.9);
  const double front_axle_load = mass * kG * (c.cg_to_rear_axle_m + c.cg_height_m * z_meas) / L;
  const double rear_axle_load = mass * kG - front_axle_load;
  // Lateral transfer from the IMU (ay > 0: left turn loads the right wheels).
  const double roll = mass * m.ay_m_s2 * c.cg_height_m;
  const std::array<double, 4> load{0.5 * front_axle_load - 0.55 * roll / c.track_front_m,
                                   0.5 * front_axle_load + 0.55 * roll / c.track_front_m,
                                   0.5 * rear_axle_load - 0.45 * roll / c.track_rear_m,
                                   0.5 * rear_axle_load + 0.45 * roll / c.track_rear_m};
  std::array<double, 4> request{};
  for (std::size_t w = 0; w < 4; ++w) {
    const double axle_force = total_N * (w < 2 ? front_share : 1.0 - front_share);
    // Share within the axle by load: the more loaded wheel carries more.
    const double axle_load = w < 2 ? front_axle_load : rear_axle_load;
    const double share = axle_load > 0.0 ? std::max(0.0, load[w]) / axle_load : 0.5;
    request[w] = axle_force * share * c.wheel_radius_m;
  }
  // One corner lost: its share goes to the other axle's wheel on the same side (the shift makes
  // no yaw moment; that wheel's slip controller keeps it within its grip).
  const std::size_t lost = lost_corner(m);
  if (p_.yaw.redistribute_lost_corner && lost < 4) {
    request[lost ^ 2U] += request[lost];
    request[lost] = 0.0;
  }
  for (std::size_t w = 0; w < 4; ++w) {
    WheelInputs in;
    in.wheel_rad_s = m.wheel_rad_s[w];
    const double half_track = 0.5 * (w < 2 ? c.track_front_m : c.track_rear_m);
    in.ground_speed_m_s = std::max(0.0, v + (w % 2 == 0 ? -1.0 : 1.0) * m.yaw_rate_rad_s * half_track);
    in.request_Nm = request[w];
    in.applied_Nm = torque_Nm(w, std::max(0.0, m.clamp_estimate_kN[w]));
    in.load_N = std::max(100.0, load[w]);
    load_in_N_[w] = in.load_N;
    if (!p_.abs_enabled) {
      out_.wheels[w] = WheelDecision{};
      out_.wheels[w].torque_Nm = in.request_Nm;
      out_.torque_Nm[w] = in.request_Nm;
      continue;
    }
    out_.wheels[w] = slip_[w].update(dt_s, in);
    out_.torque_Nm[w] = out_.wheels[w].torque_Nm;
  }
  // Yaw-moment limitation: split-mu is seen when one front wheel is under slip control with a
  // torque well below the other's; the high side may then exceed the low side only by a torque
  // that grows at a limited rate (the driver has time to counter-steer). Rear: select-low.
  // A corner the CCU cannot use (lost, failed) brakes nothing: count it as the low side, so the
  // yaw-moment limitation also acts on the asymmetry a lost front corner leaves.
  for (std::size_t w = 0; w < 4; ++w) {
    if (!m.available[w]) out_.torque_Nm[w] = 0.0;
  }
  const double driver_yaw_rate = v * m.steer_rad / (L + c.understeer_gradient_rad_s2_per_m * v * v);
  const double yaw_error = m.yaw_rate_rad_s - driver_yaw_rate;  // > 0: yawing left more than steered
  if (p_.abs_enabled && p_.yaw.enabled && p_.yaw.redistribute_lost_corner && lost < 4) {
    // A lost corner: its axle partner may exceed it (0) by what the same-side wheel of the other
    // axle balances (its extra torque over its axle partner, through the track ratio) plus a
    // moment that builds up at lost_corner_ramp_Nm_per_s, less the yaw-rate feedback.
    lost_s_ += dt_s;
    const std::size_t partner = lost ^ 1U, same_side = lost ^ 2U, diagonal = lost ^ 3U;
    const double track_ratio = lost < 2 ? c.track_rear_m / c.track_front_m : c.track_front_m / c.track_rear_m;
    const double towards_partner = partner % 2 == 1 ? -yaw_error : yaw_error;
    const double balanced = std::max(0.0, out_.torque_Nm[same_side] - out_.torque_Nm[diagonal]) * track_ratio;
    const double allowed = std::max(0.0, balanced + p_.yaw.lost_corner_initial_Nm + p_.yaw.lost_corner_ramp_Nm_per_s * lost_s_ -
                                             p_.yaw.yaw_error_gain_Nm_per_rad_s * std::max(0.0, towards_partner));
    out_.torque_Nm[partner] = std::min(out_.torque_Nm[partner], allowed);
    out_.yaw_limited = true;
  } else if (p_.abs_enabled && p_.yaw.enabled) {
    lost_s_ = 0.0;
    // The torque a wheel's tyre carries at its estimated mu (while its slip controller acts).
    auto capacity = [&](std::size_t w) {
      return out_.wheels[w].active ? std::max(0.0, out_.wheels[w].mu_estimate) * std::max(100.0, load[w]) * c.wheel_radius_m : 0.0;
    };
    // Torque per estimated wheel load (the adhesion the wheel uses): in a curve the inner wheel
    // carries less torque because it carries less load, not because its road is slippery.
    auto per_load = [&](std::size_t w, double torque_Nm) { return torque_Nm / std::max(100.0, load[w]); };
    const std::size_t low_side =
        split_ ? low_side_ : (per_load(0, out_.torque_Nm[0]) <= per_load(1, out_.torque_Nm[1]) ? 0 : 1);
    // The low side's reference: its command, but not below a share of what its tyre carries (a
    // low-mu wheel's slip controller releasing for a moment must not take the high side down with it).
    const double lo = std::max(out_.torque_Nm[low_side], p_.yaw.low_side_capacity_share * capacity(low_side));
    const double hi = out_.torque_Nm[1 - low_side];
    // Only where the slip controllers act (above their hand-over speed, where a wheel's ABS torque
    // against the other's driver torque says nothing about the road).
    const bool slip_controlled = v - std::abs(m.yaw_rate_rad_s) * 0.5 * c.track_front_m >= p_.slip.min_speed_m_s;
    const bool asym = slip_controlled && (out_.wheels[low_side].active || !m.available[low_side]) && hi > 0.0 &&
                      per_load(low_side, lo) < p_.yaw.asymmetry_ratio * per_load(1 - low_side, hi) &&
                      hi - lo > p_.yaw.min_difference_Nm &&
                      // ... and the tyres' estimated mu that far apart: on a uniform low-mu road the
                      // slip controllers' torques swing apart for a moment, their tyres' mu do not.
                      out_.wheels[1 - low_side].mu_estimate - out_.wheels[low_side].mu_estimate > p_.yaw.min_mu_difference;
    if (asym && !split_) {
      split_ = true;
      split_s_ = 0.0;
      low_side_ = low_side;
      // The heading and the reference count from here (tuning set: better than from brake onset).
      heading_error_rad_ = 0.0;
      brake_driver_yaw_rate_ = driver_yaw_rate;
      brake_steer_rad_ = m.steer_rad;
    }
    if (split_) {
      split_s_ += dt_s;
      // Braking the right (left) side more turns the car right (left), yaw rate negative (positive).
      // The reference: the yaw rate the driver steers for now, or (latch_driver_yaw_rate) the one
      // steered for when the split was seen - a driver's counter-steer against the braking's
      // moment is then no demand for yaw.
      const double error = p_.yaw.latch_driver_yaw_rate ? m.yaw_rate_rad_s - brake_driver_yaw_rate_ : yaw_error;
      const double towards_high = low_side == 0 ? -error : error;  // > 0: yawing towards the high side
      // The heading turned towards the high side since the split was seen (beyond the yaw the
      // driver steered for then).
      // (The yaw-rate error integrated, never below 0.)
      heading_error_rad_ = std::max(0.0, heading_error_rad_ + towards_high * dt_s);
      const double heading_towards_high = heading_error_rad_;
      // The driver's counter-steer (towards the low side, left positive) since the split was seen.
      const double counter_steer = (low_side == 0 ? 1.0 : -1.0) * (m.steer_rad - brake_steer_rad_);
      // The open-loop part, saturating at max_ramp_Nm (written so that below it the sum is the same
      // floating-point expression as before the bound).
      const bool saturated = p_.yaw.initial_Nm + p_.yaw.ramp_Nm_per_s * split_s_ > p_.yaw.max_ramp_Nm;
      const double open_loop = saturated ? lo + p_.yaw.max_ramp_Nm : lo + p_.yaw.initial_Nm + p_.yaw.ramp_Nm_per_s * split_s_;
      const double allowed = std::max(lo, open_loop +
                                              p_.yaw.counter_steer_gain_Nm_per_rad * std::max(0.0, counter_steer) -
                                              p_.yaw.yaw_error_gain_Nm_per_rad_s * std::max(0.0, towards_high) -
                                              p_.yaw.heading_error_gain_Nm_per_rad * heading_towards_high);
      out_.torque_Nm[1 - low_side] = std::min(out_.torque_Nm[1 - low_side], allowed);
      if (p_.yaw.rear_select_low) {
        const std::size_t rear_low = out_.torque_Nm[2] <= out_.torque_Nm[3] ? 2 : 3;
        const double rear = std::max(out_.torque_Nm[rear_low], p_.yaw.low_side_capacity_share * capacity(rear_low));
        out_.torque_Nm[2] = std::min(out_.torque_Nm[2], rear);
        out_.torque_Nm[3] = std::min(out_.torque_Nm[3], rear);
      }
    }
    // Yaw-moment build-up delay before the split is seen (GMA): the first time in a stop that one
    // wheel of an axle goes into slip control while its partner does not, the partner is held at
    // the torque its caliper applies then and rises at most at pre_split_ramp_Nm_per_s until it
    // also goes into slip control or the split is seen. On a uniform road the partner follows
    // within a few periods; on split-mu the high side's force no longer builds up while the
    // detection waits for the tyres' mu estimates to part.
    if (p_.yaw.pre_split_ramp_Nm_per_s > 0.0) {
      for (std::size_t axle = 0; axle < 2; ++axle) {
        PreSplitHold& h = pre_[axle];
        const std::size_t a = 2 * axle, b = a + 1;
        if (split_ || z_request <= 0.0) {
          h.holding = false;
        } else if (!h.holding && !h.done && m.available[a] && m.available[b] &&
                   out_.wheels[a].active != out_.wheels[b].active) {
          h.holding = true;
          h.done = true;
          h.wheel = out_.wheels[a].active ? b : a;
          h.s = 0.0;
          h.hold_Nm = torque_Nm(h.wheel, std::max(0.0, m.clamp_estimate_kN[h.wheel]));
        }
        if (h.holding) {
          if (out_.wheels[h.wheel].active) {
            h.holding = false;
          } else {
            h.s += dt_s;
            out_.torque_Nm[h.wheel] = std::min(out_.torque_Nm[h.wheel], h.hold_Nm + p_.yaw.pre_split_ramp_Nm_per_s * h.s);
          }
        }
        if (z_request <= 0.0) h.done = false;
      }
    }
    if (z_request <= 0.0) split_ = false;
  }
  out_.split_mu = split_;
  if (lost >= 4 || !p_.yaw.redistribute_lost_corner) out_.yaw_limited = split_;
  for (std::size_t w = 0; w < 4; ++w) {
    out_.clamp_force_kN[w] = m.available[w] ? clamp_kN(w, out_.torque_Nm[w]) : 0.0;
    // Under slip control the pads stay in contact: releasing through the air gap costs its
    // closing time (about 45 ms) on every re-apply.
    if (m.available[w] && out_.wheels[w].active && z_request > 0.0)
      out_.clamp_force_kN[w] = std::max(out_.clamp_force_kN[w], p_.slip.active_min_clamp_kN);
    slip_[w].commanded(torque_Nm(w, out_.clamp_force_kN[w]));  // the caliper model's input
  }
  return out_;
}

}  // namespace bbw::brake
