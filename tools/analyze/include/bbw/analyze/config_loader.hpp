// Loads AnalysisOptions from YAML through the strict reader. Every key is optional (the struct's
// default stands); an unknown key, a wrong type or an out-of-range value is an error naming the
// file, line and key.
#pragma once

#include <string>

#include "bbw/analysis/options.hpp"
#include "bbw/common/strict_yaml.hpp"

namespace bbw::analyze {

analysis::AnalysisOptions load_options(config::Reader& r);
analysis::AnalysisOptions load_options_file(const std::string& file);

}  // namespace bbw::analyze
