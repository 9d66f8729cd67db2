// Records one corner of a scenario with the plant, in process (no DDS, no files): the same
// CornerSim the corner process runs. Used by the accuracy tests, the ablation tool and the
// calibrator benchmark.
#pragma once

#include <cstddef>

#include "bbw/calibration/offline.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::calibration {

// time, resolver position and speed, internal load cell; truth = the external sensor.
Recording record_corner(const bbw::scenario::Scenario& scenario, std::size_t corner_index);

}  // namespace bbw::calibration
