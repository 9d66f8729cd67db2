// Loads MonitorParams from YAML (config/faults/monitor.yaml) with the strict reader: every key
// required, unknown keys refused, ranges checked with file, line and key; then
// MonitorParams::validate() for the rules between fields. Target bbw_fault_monitor_config (the
// monitor itself stays free of files).
#pragma once

#include <string>

#include "bbw/common/strict_yaml.hpp"
#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

MonitorParams load_monitor_params(const std::string& file);
MonitorParams read_monitor_params(bbw::config::Reader& r);

}  // namespace bbw::faults
