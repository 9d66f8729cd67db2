// One corner in simulation: plant + sensors + local controller + reference profile. Both the
// offline simulator and the DDS corner process step this same class, so they produce the same
// numbers for the same scenario, corner and inputs. Pure: time advances only through step().
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "bbw/corner_unit/controller.hpp"
#include "bbw/model/curve.hpp"
#include "bbw/plant/clamp_curve.hpp"
#include "bbw/plant/plant.hpp"
#include "bbw/scenario/profile.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::scenario {

enum class CommandKind { Position, Force };

// One sample of a corner: the plant's sensor readings (plant::Measurement: time, resolver
// position and speed, load cell, external force, temperature, motor current; the one shape of
// a sensor reading on the corner's side of the wire, after any fault injection) plus what the
// corner adds: its sequence number, the local loop's command, and the simulation's ground truth
// (*_true fields, not available to a real corner).
struct CornerSample : plant::Measurement {
  std::uint64_t seq = 0;            // 1 for the first step
  double force_true_kN = 0.0;       // truth
  CommandKind command_kind = CommandKind::Position;
  double command = 0.0;             // position_rev or force_kN, per command_kind
  double current_command_A = 0.0;
  double force_feedback_kN = 0.0;   // what the force loop used (0 in position mode)
  double friction_true_kN = 0.0;    // truth: all friction in the load cell (key + viscous)
  double position_true_rev = 0.0;   // truth: spindle position
};

// A curve estimate from the calibrator: F = ((A x + B) x + C) x + D, kN with x in rev.
// A force loop's curve estimate: the calibrated cubic, held at its least value below its local
// minimum. A cubic fitted over the caliper's range rises again below that minimum (the released
// end, where it was never fitted); a loop on the raw polynomial there read more force the further
// it released, released the more and ran a healthy drive back onto its retracted stop while
// force was commanded. Held, the estimate never rises as the position falls.
struct CurveEstimate {
  double a = 0.0, b = 0.0, c = 0.0, d = 0.0;
  double cubic_kN(double x_rev) const { return model::Curve{a, b, c, d}.force_kN(x_rev); }
  double local_min_rev() const { return model::Curve{a, b, c, d}.local_min_rev(); }
  double force_kN(double x_rev) const {
    const double x_min = local_min_rev();
    return cubic_kN(x_rev < x_min ? x_min : x_rev);
  }
};

// A hook between the sensors and everything that reads them (fault injection, docs/faults.md):
// called once per step with the new readings, before the sample and the local controller see
// them. It may change any reading; a non-finite reading reaches the sample as it is, while the
// local controller keeps using the last finite value of that channel.
class SensorHook {
 public:
  virtual void apply(plant::Measurement& readings) = 0;

 protected:
  ~SensorHook() = default;
};

// What the outside (the CCU) may supply each step.
struct ExternalInputs {
  // A clamp-force command; when present it replaces the profile and the corner runs in force
  // mode (whatever its drive mode), using the corner's feedback choice (load_cell for a
  // position-driven corner).
  std::optional<double> force_command_kN;
  // For feedback `compensated`: the friction the load cell is believed to contain.
  double friction_estimate_kN = 0.0;
  // For feedback `curve`: the calibrated curve; without one the load cell is used.
  std::optional<CurveEstimate> curve;
  // Replaces the corner's force-feedback choice in force mode (a CCU fault reaction: a faulty
  // load cell -> Curve). Position-driven corners without a force command are unaffected.
  std::optional<corner_unit::ForceFeedback> feedback;
  // Fault injection (docs/faults.md): the plant's torque scale for this step (1 = healthy) and
  // an optional sensor hook; neither changes anything at their defaults.
  double torque_scale = 1.0;
  bool actuator_seized = false;  // the mechanism jams (plant::PlantInputs::seized)
  // The caliper's temperature from a vehicle run (plant::PlantInputs::temperature_C); NaN: the
  // corner's own conditions.
  double temperature_C = std::numeric_limits<double>::quiet_NaN();
  SensorHook* sensor_hook = nullptr;
};

class CornerSim {
 public:
  // Builds corner `index` of the scenario. Throws std::invalid_argument / std::out_of_range.
  CornerSim(const Scenario& scenario, std::size_t index);

  // Advances by dt_s and returns the new sample. Allocation-free.
  const CornerSample& step(double dt_s, const ExternalInputs& ext = {});

  // Starts the corner's clock at time_s instead of 0 (a corner process restarted mid-run joins
  // the scenario's time base; issue 5). Only before the first step; the plant is at its
  // initial (released) state and the sequence starts at 1.
  void start_at(double time_s);

  const CornerSample& last() const { return sample_; }
  const std::string& name() const { return name_; }
  const plant::Plant& plant() const { return plant_; }
  const corner_unit::LocalController& controller() const { return controller_; }
  double time_s() const { return time_s_; }
  // The force-feedback choice in force mode.
  corner_unit::ForceFeedback feedback() const { return feedback_; }

 private:
  // The curve feedback's estimate at the held position (see eol_curve_).
  double curve_estimate_kN(const CurveEstimate& curve) const;

  std::string name_;
  plant::Plant plant_;
  corner_unit::LocalController controller_;
  // The caliper's end-of-line curve (its production-line measurement, the same the CCU's monitor
  // holds): the curve feedback's estimate below the calibrated cubic's minimum.
  plant::ClampCurve eol_curve_;
  DriveMode mode_;
  corner_unit::ForceFeedback feedback_;
  std::optional<PositionProfile> position_profile_;
  std::optional<BreakpointProfile> force_profile_;
  double force_scale_ = 1.0;        // demand drive: axle factor * max clamp force
  double time_s_ = 0.0;
  std::uint64_t seq_ = 0;
  plant::Measurement readings_;     // the sensor readings as seen (after any SensorHook)
  double held_position_rev_ = 0.0;  // last finite readings, for the local controller
  double held_speed_rev_per_s_ = 0.0;
  double held_load_cell_kN_ = 0.0;
  // The source the force loop read last step (curve feedback without a curve is the load cell);
  // none before the first force-mode step.
  std::optional<corner_unit::ForceFeedback> last_feedback_source_;
  double held_temperature_C_ = 0.0;
  CornerSample sample_;
};

}  // namespace bbw::scenario
