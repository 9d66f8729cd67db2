#include "bbw/scenario/corner_sim.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bbw::scenario {
namespace {

plant::PlantParams corner_plant(const Scenario& s, std::size_t index) {
  plant::PlantParams p = s.plant;
  p.sensors = s.corners[index].sensors;
  return p;
}

const CornerSpec& corner_at(const Scenario& s, std::size_t index) {
  if (index >= s.corners.size()) {
    throw std::out_of_range("CornerSim: scenario '" + s.name + "' has no corner " + std::to_string(index));
  }
  return s.corners[index];
}

corner_unit::ControllerParams corner_controller(const Scenario& s) {
  corner_unit::ControllerParams c = s.controller;
  c.actuator = actuator_model(s.plant);
  c.current_limit_A = s.plant.motor.current_limit_A;
  return c;
}

// Below this end-of-line force at the cubic's minimum the pads barely touch: the minimum is held.
constexpr double kEolFloor_kN = 0.05;

}  // namespace

CornerSim::CornerSim(const Scenario& scenario, std::size_t index)
    : name_(corner_at(scenario, index).name),
      plant_(corner_plant(scenario, index), scenario.corners[index].effects, scenario.corners[index].conditions,
             corner_seed(scenario.seed, index), scenario.plant_dt_s),
      controller_(corner_controller(scenario)),
      eol_curve_(scenario.plant.curve),
      mode_(scenario.corners[index].drive.mode),
      feedback_(scenario.corners[index].drive.feedback) {
  const CornerSpec& c = scenario.corners[index];
  switch (mode_) {
    case DriveMode::Position:
      position_profile_.emplace(c.drive.position);
      plant_.reset(c.drive.position.start_rev);
      break;
    case DriveMode::Force:
      force_profile_.emplace(c.drive.force_kN);
      plant_.reset(controller_.params().release_position_rev);
      break;
    case DriveMode::Demand: {
      if (!scenario.demand) throw std::invalid_argument("corner " + c.name + ": demand drive needs a scenario demand");
      const auto axle = c.axle ? c.axle : axle_from_name(c.name);
      if (!axle) throw std::invalid_argument("corner " + c.name + ": demand drive needs an axle");
      force_profile_.emplace(scenario.demand->profile);
      force_scale_ = scenario.demand->max_clamp_force_kN * scenario.demand->axle_factor(*axle);
      plant_.reset(controller_.params().release_position_rev);
      break;
    }
  }
  const plant::Measurement& m = plant_.measurement();
  readings_ = m;
  held_position_rev_ = m.position_rev;
  held_speed_rev_per_s_ = m.speed_rev_per_s;
  held_load_cell_kN_ = m.force_internal_kN;
  held_temperature_C_ = std::isfinite(m.temperature_C) ? m.temperature_C : scenario.plant.curve.reference_temperature_C;
  sample_.position_rev = m.position_rev;
  sample_.force_internal_kN = m.force_internal_kN;
  sample_.force_external_kN = m.force_external_kN;
  sample_.force_true_kN = plant_.state().force_true_kN;
  sample_.temperature_C = m.temperature_C;
  sample_.position_true_rev = plant_.state().position_rev;
}

const CornerSample& CornerSim::step(double dt_s, const ExternalInputs& ext) {
  if (!(dt_s > 0.0)) return sample_;
  const double t_next = time_s_ + dt_s;
  // The controller sees the readings as delivered, with non-finite ones held at the last
  // finite value (a sensor that gave no value this step).
  const plant::Measurement& m = readings_;
  if (std::isfinite(m.position_rev)) held_position_rev_ = m.position_rev;
  if (std::isfinite(m.speed_rev_per_s)) held_speed_rev_per_s_ = m.speed_rev_per_s;
  if (std::isfinite(m.force_internal_kN)) held_load_cell_kN_ = m.force_internal_kN;
  if (std::isfinite(m.temperature_C)) held_temperature_C_ = m.temperature_C;
  corner_unit::ControllerInputs in;
  in.position_rev = held_position_rev_;
  in.speed_rev_per_s = held_speed_rev_per_s_;
  in.load_force_kN = held_load_cell_kN_;
  corner_unit::ControllerOutput out;
  const bool force_mode = ext.force_command_kN.has_value() || mode_ != DriveMode::Position;
  if (force_mode) {
    double cmd = 0.0, rate = 0.0;
    if (ext.force_command_kN) {
      cmd = *ext.force_command_kN;
    } else {
      const Reference r = force_profile_->at(t_next);
      cmd = force_scale_ * r.value;
      rate = force_scale_ * r.rate;
    }
    corner_unit::ForceSources src;
    src.load_cell_kN = held_load_cell_kN_;
    src.friction_estimate_kN = ext.friction_estimate_kN;
    src.curve_estimate_kN = ext.curve ? curve_estimate_kN(*ext.curve) : held_load_cell_kN_;
    src.true_kN = plant_.state().force_true_kN;
    const auto fb = ext.feedback ? *ext.feedback
                    : mode_ == DriveMode::Position ? corner_unit::ForceFeedback::LoadCell
                                                   : feedback_;
    in.force_feedback_kN = corner_unit::select_force(fb, src);
    const auto source = fb == corner_unit::ForceFeedback::Curve && !ext.curve ? corner_unit::ForceFeedback::LoadCell : fb;
    in.feedback_switched = last_feedback_source_ && source != *last_feedback_source_;
    last_feedback_source_ = source;
    out = controller_.update_force(cmd, in, dt_s, rate);
    sample_.command_kind = CommandKind::Force;
    sample_.command = cmd;
  } else {
    const Reference r = position_profile_->at(t_next);
    out = controller_.update_position(corner_unit::PositionReference{r.value, r.rate, r.accel}, in, dt_s);
    sample_.command_kind = CommandKind::Position;
    sample_.command = r.value;
  }
  sample_.force_feedback_kN = in.force_feedback_kN;
  sample_.current_command_A = out.current_command_A;

  readings_ = plant_.step(plant::PlantInputs{out.current_command_A, ext.torque_scale, ext.actuator_seized, ext.temperature_C}, dt_s);
  if (ext.sensor_hook != nullptr) ext.sensor_hook->apply(readings_);
  const plant::Measurement& y = readings_;
  const plant::PlantState& s = plant_.state();
  time_s_ = t_next;
  static_cast<plant::Measurement&>(sample_) = y;
  sample_.seq = ++seq_;
  sample_.time_s = time_s_;  // the corner's clock (the plant's is the same sum of steps)
  sample_.force_true_kN = s.force_true_kN;
  sample_.friction_true_kN = s.friction_kN;
  sample_.position_true_rev = s.position_rev;
  return sample_;
}

double CornerSim::curve_estimate_kN(const CurveEstimate& curve) const {
  // Below the lowest position the cubic is trusted at (controller.curve_trusted_min_rev, or its
  // local minimum if higher: below that it rises again as the drive releases) the estimate is the
  // end-of-line curve scaled to meet the cubic there: continuous, rising with the position, 0 at
  // the pads' contact. A cubic cannot bend to the contact: on the raw polynomial the loop read
  // 5.4 kN at 1.6 rev (tuning seed 1403 run 646) or 2.4 kN at the released home (seed 1408 run
  // 284) and released onto its stop, or held there, while a smaller force was commanded.
  const double x = held_position_rev_;
  const double x_low = std::max(curve.local_min_rev(), controller_.params().curve_trusted_min_rev);
  if (!(x < x_low)) return curve.cubic_kN(x);
  const double f_low_kN = curve.cubic_kN(x_low);
  const double eol_low_kN = eol_curve_.force_kN(x_low, held_temperature_C_, 0.0);
  if (!(f_low_kN > 0.0) || !(eol_low_kN > kEolFloor_kN)) return curve.force_kN(x);  // no contact there
  // Behind the pads' contact the end-of-line curve is flat at 0; there the estimate goes on down
  // at the loop's own slope at zero force, so a loop that overshot the contact still reads how
  // far (without it, stress seed 1406 run 81 overshot to -0.6 rev and was named actuator_tracking).
  const double contact_rev = eol_curve_.contact_rev(held_temperature_C_, 0.0);
  return f_low_kN * eol_curve_.force_kN(x, held_temperature_C_, 0.0) / eol_low_kN -
         controller_.params().stiffness_at_zero_kN_per_rev * std::max(0.0, contact_rev - x);
}

void CornerSim::start_at(double time_s) {
  if (seq_ != 0) throw std::logic_error("CornerSim::start_at after the first step");
  if (!std::isfinite(time_s) || time_s < 0.0) throw std::invalid_argument("CornerSim::start_at: time must be finite and >= 0");
  time_s_ = time_s;
  sample_.time_s = time_s;
}

}  // namespace bbw::scenario
