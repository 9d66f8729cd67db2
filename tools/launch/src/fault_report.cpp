#include "fault_report.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

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

const faults::Finding kFindings[] = {
    faults::Finding::LoadCellOffset, faults::Finding::LoadCellStuck,   faults::Finding::LoadCellNoisy,
    faults::Finding::LoadCellMissing, faults::Finding::ResolverOffset, faults::Finding::ResolverStuck,
    faults::Finding::ActuatorTorqueLoss, faults::Finding::ActuatorLost, faults::Finding::ActuatorTracking,
    faults::Finding::ActuatorNotReleasing,
    faults::Finding::LinkLost,        faults::Finding::ProcessLost};

const char* reaction_for(const std::string& finding) {
  for (faults::Finding f : kFindings) {
    if (finding == faults::to_string(f)) return faults::reaction_to(f);
  }
  return "none";
}

}  // namespace

std::vector<FaultResult> assess_faults(const faults::FaultSchedule& schedule, const std::vector<Detection>& detections,
                                       const std::map<std::string, double>& ccu_lost_s,
                                       const std::vector<TimelinePoint>& timeline, double run_end_s) {
  std::vector<FaultResult> out;
  for (const faults::FaultSpec& f : schedule.faults) {
    FaultResult r;
    r.fault = f;
    const double end_s = std::min(f.end_s(), run_end_s);
    r.delivered_share = share(timeline, f.at_s, end_s);
    if (f.target == faults::Target::CCU) {
      // The corners' watchdogs detect a lost CCU; the diagnosis is right when every corner did.
      double first = std::numeric_limits<double>::infinity();
      bool all = !ccu_lost_s.empty();
      for (const auto& [corner, t] : ccu_lost_s) {
        if (t >= f.at_s - 1e-9) first = std::min(first, t);
        all = all && t >= f.at_s - 1e-9;
      }
      if (std::isfinite(first)) {
        r.detected = true;
        r.detected_s = r.diagnosis_s = first;
        r.latency_ms = r.diagnosis_latency_ms = 1e3 * (first - f.at_s);
        r.diagnosis = "ccu_lost";
        r.correct = all;
        r.reaction = "corners hold the last command, then ramp to the default clamp force (never release)";
      }
      out.push_back(r);
      continue;
    }
    const std::string corner = faults::to_string(f.target);
    const std::string expected = faults::to_string(f.type == faults::FaultType::Kill ? faults::Part::Process : f.part);
    const Detection* best = nullptr;
    const Detection* first = nullptr;
    for (const Detection& d : detections) {
      if (d.corner != corner || d.detected_s < f.at_s - 1e-9) continue;
      if (first == nullptr || d.detected_s < first->detected_s) first = &d;
      const bool right = d.part == expected;
      if (best == nullptr) {
        best = &d;
      } else {
        const bool best_right = best->part == expected;
        if ((right && !best_right) || (right == best_right && d.detected_s < best->detected_s)) best = &d;
      }
    }
    if (best != nullptr) {
      r.detected = true;
      r.detected_s = first->detected_s;
      r.latency_ms = 1e3 * (first->detected_s - f.at_s);
      r.diagnosis_s = best->detected_s;
      r.diagnosis_latency_ms = 1e3 * (best->detected_s - f.at_s);
      // The diagnosis is that part's final finding: a later upgrade of the same part (e.g.
      // actuator_lost -> actuator_not_releasing once a release is commanded) refines it.
      const Detection* last = best;
      for (const Detection& d : detections) {
        if (d.corner == corner && d.part == best->part && d.detected_s >= last->detected_s) last = &d;
      }
      r.diagnosis = last->finding;
      r.correct = best->part == expected;
      r.reaction = reaction_for(last->finding);
    }
    out.push_back(r);
  }
  return out;
}

}  // namespace bbw::launch
