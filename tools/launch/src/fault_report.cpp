#include "fault_report.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "bbw/faults/fault_monitor.hpp"
#include "bbw/faults/outcome.hpp"
#include "bbw/node/command_plan.hpp"

namespace bbw::launch {

std::vector<TimelinePoint> build_timeline(const scenario::Scenario& s,
                                          const std::vector<std::vector<std::pair<double, double>>>& logs) {
  const double T = s.ccu_period_s;
  const auto periods = static_cast<std::size_t>(std::ceil(s.duration_s / T - 1e-9));
  std::vector<TimelinePoint> out(periods);
  const ccu::CommandPlanner planner(s);
  for (std::size_t k = 0; k < periods; ++k) {
    out[k].time_s = static_cast<double>(k + 1) * T;
    const double t_start = static_cast<double>(k) * T;
    for (std::size_t i = 0; i < s.corners.size(); ++i) {
      const ccu::PlannedCommand p = planner.at(i, t_start);
      if (p.mode == ccu::CommandMode::Force) out[k].demand_kN += p.clamp_force_kN;
    }
  }
  for (const auto& log : logs) {
    for (const auto& [t, f] : log) {
      const long long k = std::llround(t / T) - 1;
      if (k >= 0 && static_cast<std::size_t>(k) < periods && std::isfinite(f)) out[static_cast<std::size_t>(k)].delivered_kN += f;
    }
  }
  return out;
}

namespace {

double share(const std::vector<TimelinePoint>& tl, double from_s, double to_s) {
  double d = 0.0, g = 0.0;
  for (const auto& p : tl) {
    if (p.time_s < from_s || p.time_s >= to_s) continue;
    d += p.demand_kN;
    g += p.delivered_kN;
  }
  return d > 0.0 ? g / d : 1.0;
}

}  // namespace

std::vector<faults::DetectionEvent> detection_events(const std::vector<Detection>& detections) {
  // ccu.stats names corners and findings; the scorer takes them typed.
  std::vector<faults::DetectionEvent> events;
  for (const Detection& d : detections) {
    const auto corner = faults::target_from_name(d.corner);
    const faults::Finding finding = faults::finding_from_name(d.finding);
    if (!corner || faults::is_ccu(*corner)) throw std::runtime_error("detection of an unknown corner '" + d.corner + "'");
    if (finding == faults::Finding::None) throw std::runtime_error("detection of an unknown finding '" + d.finding + "'");
    events.push_back({*corner, finding, d.onset_s, d.detected_s});
  }
  return events;
}

std::vector<faults::DetectionEvent> false_alarms(const faults::FaultSchedule& schedule, const std::vector<Detection>& detections) {
  return faults::score_run(schedule.faults, detection_events(detections)).false_alarms;
}

std::vector<FaultResult> assess_faults(const faults::FaultSchedule& schedule, const std::vector<Detection>& detections,
                                       const std::map<std::string, double>& ccu_lost_s,
                                       const std::vector<TimelinePoint>& timeline, double run_end_s) {
  const faults::RunScore score = faults::score_run(schedule.faults, detection_events(detections), run_end_s);
  std::vector<double> lost;
  for (const auto& [corner, t] : ccu_lost_s) lost.push_back(t);
  std::vector<FaultResult> out;
  std::size_t next = 0;  // score.outcomes: the corner faults in schedule order
  for (const faults::FaultSpec& f : schedule.faults) {
    FaultResult r = faults::is_ccu(f.target) ? faults::score_ccu_kill(f, lost) : score.outcomes.at(next++);
    r.delivered_share = share(timeline, f.at_s, std::min(f.end_s(), run_end_s));
    out.push_back(r);
  }
  return out;
}

}  // namespace bbw::launch
