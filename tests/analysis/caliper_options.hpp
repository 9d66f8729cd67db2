// Analysis options for a caliper recording (position in rev), as bbw_analyze runs it: the
// friction is the shipped online calibrator's element set (calibration::friction_thresholds_rev
// of config/calibrator/robust.yaml), not a Delta_max searched on a grid.
#pragma once

#include <cstdlib>
#include <string>

#include "bbw/analysis/options.hpp"
#include "bbw/calibration/config.hpp"
#include "bbw/calibration/config_yaml.hpp"

namespace bbw::test {

inline analysis::AnalysisOptions caliper_options() {
  const char* s = std::getenv("BBW_SOURCE_DIR");
  const std::string dir = s ? s : BBW_SOURCE_DIR_FALLBACK;
  analysis::AnalysisOptions o;
  o.friction_thresholds =
      calibration::friction_thresholds_rev(calibration::load_config(dir + "/config/calibrator/robust.yaml"));
  return o;
}

}  // namespace bbw::test
