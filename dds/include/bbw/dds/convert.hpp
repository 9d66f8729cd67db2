// The one place where DDS message types and domain structs meet. Every process converts here,
// so a field's unit and meaning are decided once.
#pragma once

#include <bbw/idl/bbw_msgs.h>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/model/friction_tracker.hpp"
#include "bbw/scenario/corner_sim.hpp"

namespace bbw::dds {

// Corner side: one simulated step into a wire sample (truth flagged as simulation-only).
void to_msg(const scenario::CornerSample& in, bool force_comp_used, msg::MeasurementSample& out);

// CCU side: the calibrator's current model into a CalibrationState message.
void to_msg(const calibration::Calibrator& calibrator, std::uint8_t corner_id, std::uint64_t version,
            double time_s, msg::CalibrationState& out);

// Corner side: the model a corner applies. Returns false (and leaves `out` alone) when the
// message is malformed (sizes differ, non-finite numbers, negative thresholds).
struct CalibrationModel {
  scenario::CurveEstimate curve;
  calibration::FrictionModel friction;  // the curve's coefficients too (load-dependent term)
  std::uint64_t version = 0;
};
bool from_msg(const msg::CalibrationState& in, CalibrationModel& out);

}  // namespace bbw::dds
