// A vehicle run (issue 15): bbw_vehicle's OUT/vehicle.json ({"vehicle": {...}}) merged into
// OUT/summary.json as its `vehicle` object. Throws std::runtime_error when either is unreadable.
#pragma once

#include <string>

namespace bbw::launch {

void merge_vehicle_summary(const std::string& out_dir);

}  // namespace bbw::launch
