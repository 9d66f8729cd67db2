// Loads a CalibratorConfig from YAML (config/calibrator/*.yaml) with the strict reader:
// unknown, missing, wrong-type and out-of-range keys stop with file, line, key and rule.
#pragma once

#include <string>

#include "bbw/calibration/config.hpp"
#include "bbw/common/strict_yaml.hpp"

namespace bbw::calibration {

CalibratorConfig load_config(const std::string& file);
// Reads the keys of one calibrator mapping (also used inside scenario files).
CalibratorConfig read_config(bbw::config::Reader& r);
// The config as YAML that read_config reads back to the same values (every key, numbers at
// full precision): e.g. a CCU's per-corner start (faults::calibrator_start) for ./bbw calibrate.
std::string to_yaml(const CalibratorConfig& c);

}  // namespace bbw::calibration
