#include "bbw/node/command_plan.hpp"

#include <stdexcept>

namespace bbw::ccu {

CommandPlanner::CommandPlanner(const scenario::Scenario& s) {
  for (const auto& c : s.corners) {
    modes_.push_back(c.drive.mode);
    if (c.drive.mode == scenario::DriveMode::Demand) {
      if (!s.demand) throw std::invalid_argument(s.file + ": corner " + c.name + " is demand-driven but there is no demand");
      const auto axle = c.axle ? c.axle : scenario::axle_from_name(c.name);
      if (!axle) throw std::invalid_argument(s.file + ": corner " + c.name + " has no axle");
      axle_factor_.push_back(s.demand->axle_factor(*axle));
    } else {
      axle_factor_.push_back(0.0);
    }
  }
  if (s.demand) {
    demand_.emplace(s.demand->profile);
    max_clamp_force_kN_ = s.demand->max_clamp_force_kN;
  }
}

PlannedCommand CommandPlanner::at(std::size_t i, double time_s) const {
  PlannedCommand p;
  if (modes_.at(i) == scenario::DriveMode::Demand) {
    p.mode = CommandMode::Force;
    p.clamp_force_kN = demand_->at(time_s).value * max_clamp_force_kN_ * axle_factor_[i];
  }
  return p;
}

}  // namespace bbw::ccu
