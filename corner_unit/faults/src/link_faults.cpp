#include "bbw/faults/link_faults.hpp"

#include <algorithm>

namespace bbw::faults {

LinkFaults::LinkFaults(const FaultSchedule& schedule, Target target) : target_(target) {
  for (const FaultSpec& f : schedule.faults) {
    if (f.target == target && (f.part == Part::Network || f.part == Part::Process)) faults_.push_back(f);
  }
}

bool LinkFaults::silenced(double time_s) const {
  return std::any_of(faults_.begin(), faults_.end(),
                     [&](const FaultSpec& f) { return f.type == FaultType::Silence && f.active_at(time_s); });
}

double LinkFaults::delay_s(double time_s) const {
  double d = 0.0;
  for (const FaultSpec& f : faults_) {
    if (f.type == FaultType::Delay && f.active_at(time_s)) d = std::max(d, f.delay_ms * 1e-3);
  }
  return d;
}

bool LinkFaults::killed(double time_s) const {
  return std::any_of(faults_.begin(), faults_.end(),
                     [&](const FaultSpec& f) { return f.type == FaultType::Kill && f.active_at(time_s); });
}

std::vector<ProcessAction> process_actions(const FaultSchedule& schedule) {
  std::vector<ProcessAction> out;
  for (const FaultSpec& f : schedule.faults) {
    if (f.type == FaultType::Hang) {
      out.push_back({f.at_s, f.target, ProcessAction::Kind::Hang});
      if (f.resume_after_s) out.push_back({f.at_s + *f.resume_after_s, f.target, ProcessAction::Kind::Resume});
      continue;
    }
    if (f.type != FaultType::Kill) continue;
    out.push_back({f.at_s, f.target, ProcessAction::Kind::Kill});
    if (f.restart_after_s) out.push_back({f.at_s + *f.restart_after_s, f.target, ProcessAction::Kind::Restart});
  }
  std::stable_sort(out.begin(), out.end(), [](const ProcessAction& a, const ProcessAction& b) { return a.at_s < b.at_s; });
  return out;
}

}  // namespace bbw::faults
