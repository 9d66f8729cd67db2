// Loads AnalysisOptions from YAML through the strict reader. Every key is optional (the struct's
// default stands); an unknown key, a wrong type or an out-of-range value is an error naming the
// file, line and key.
#pragma once

#include <string>
#include <vector>

#include "bbw/analysis/options.hpp"
#include "bbw/common/strict_yaml.hpp"

namespace bbw::analyze {

analysis::AnalysisOptions load_options(config::Reader& r);
analysis::AnalysisOptions load_options_file(const std::string& file);

// The friction structure of the online calibrator, from the one place it is computed
// (calibration::friction_thresholds_rev): the thresholds of `calibrator_file`'s config, or of the
// shipped config/calibrator/robust.yaml when `calibrator_file` is empty and the position is in
// rev. Empty (Delta_max searched on a grid) for "none" or a position in another unit, where the
// product's element set in rev means nothing.
std::vector<double> calibrator_friction_thresholds(const std::string& calibrator_file, const std::string& position_unit);

}  // namespace bbw::analyze
