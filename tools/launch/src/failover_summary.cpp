#include "failover_summary.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "bbw/common/csv.hpp"
#include "bbw/node/command_plan.hpp"
#include "bbw/runtime/command_owner.hpp"
#include "bbw/runtime/run_stats.hpp"

namespace bbw::launch {

namespace {

// The tracking error (planned demand - true force) of the periods ending in (from_s, to_s]:
// its mean and its largest value (0 and 0 when no force-mode period lies there).
struct ErrorStats {
  double mean_kN = 0.0, max_kN = 0.0;
  int n = 0;
};
ErrorStats tracking_error(const ccu::CommandPlanner& planner, std::size_t corner, double T,
                          const std::vector<std::pair<double, double>>& periods, double from_s, double to_s) {
  ErrorStats e;
  double sum = 0.0;
  e.max_kN = -std::numeric_limits<double>::infinity();
  for (const auto& [t_end, force_kN] : periods) {
    if (!(t_end > from_s + 1e-9 && t_end <= to_s + 1e-9) || !std::isfinite(force_kN)) continue;
    const ccu::PlannedCommand p = planner.at(corner, t_end - T);
    if (p.mode != ccu::CommandMode::Force) continue;
    const double err = p.clamp_force_kN - force_kN;
    sum += err;
    e.max_kN = std::max(e.max_kN, err);
    ++e.n;
  }
  if (e.n == 0) return {};
  e.mean_kN = sum / e.n;
  return e;
}

}  // namespace

FailoverInput load_failover_input(const scenario::Scenario& scenario, const std::string& out_dir, bool lockstep) {
  FailoverInput in;
  in.scenario = &scenario;
  in.lockstep = lockstep;
  in.primary = runtime::load_ccu_failover(out_dir + "/ccu_failover.stats");
  in.standby = runtime::load_ccu_failover(out_dir + "/standby/ccu_failover.stats");
  for (const auto& corner : scenario.corners) {
    const std::string& c = corner.name;
    FailoverCornerInput ci;
    ci.owners = runtime::load_corner_failover(out_dir + "/corner_" + c + "_failover.stats");
    ci.ccu_lost_s = runtime::load_corner_stats(out_dir + "/corner_" + c + ".stats").ccu_lost_s;
    csv::ReadOptions o;
    o.required = {"time_s", "force_true_kN"};
    const auto t = csv::read(out_dir + "/corner_" + c + "_periods.csv", o);
    for (std::size_t r = 0; r < t.rows(); ++r) ci.periods.emplace_back(t.column("time_s")[r], t.column("force_true_kN")[r]);
    in.corners.push_back(std::move(ci));
  }
  return in;
}

FailoverResult assess_failover(const FailoverInput& in) {
  if (in.scenario == nullptr) throw std::invalid_argument("assess_failover: no scenario");
  FailoverResult r;
  const double T = in.scenario->ccu_period_s;
  double failed_mono = -1.0;
  if (in.primary.failed_sim_s >= 0.0) {
    r.failure = in.primary.failure;
    r.failed_s = in.primary.failed_sim_s;
    failed_mono = in.primary.failed_mono_s;
  } else if (in.failed_sim_s >= 0.0) {
    r.failure = in.failure;
    r.failed_s = in.failed_sim_s;
    failed_mono = in.failed_mono_s;
  }
  r.standby_failed_s = in.standby.failed_sim_s;
  r.demoted_s = in.primary.demoted_sim_s;
  r.demote_reason = in.primary.demote_reason;
  r.primary_outages = static_cast<int>(in.primary.outages);
  r.standby_outages = static_cast<int>(in.standby.outages);
  r.primary_stalls = static_cast<int>(in.primary.stalls);
  r.standby_stalls = static_cast<int>(in.standby.stalls);
  const ccu::CommandPlanner planner(*in.scenario);
  double takeover_mono = -std::numeric_limits<double>::infinity();
  double takeover_sim = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < in.corners.size(); ++i) {
    const FailoverCornerInput& c = in.corners[i];
    const auto& sw = c.owners.switches;
    r.commands_stale += static_cast<long long>(c.owners.commands_stale);
    r.owners_at_end += (i == 0 ? "" : ",") + (sw.empty() ? std::string("none") : sw.back().to);
    r.max_command_gap_wall_ms = std::max(r.max_command_gap_wall_ms, c.owners.max_gap_mono_ms);
    r.max_command_gap_ms = std::max(r.max_command_gap_ms, in.lockstep ? c.owners.max_gap_sim_ms : c.owners.max_gap_mono_ms);
    if (c.ccu_lost_s >= 0.0) {
      r.safe_state_entered = true;
      r.safe_state_s = r.safe_state_s < 0.0 ? c.ccu_lost_s : std::min(r.safe_state_s, c.ccu_lost_s);
    }
    // Changes the corner did not keep lie between the first kKeepFirst and the rest.
    const std::size_t gap_at = c.owners.switches_dropped > 0 ? runtime::CommandOwnerTracker::kKeepFirst : sw.size();
    if (failed_mono < 0.0) {
      for (const auto& x : sw) r.switches_before_failure += x.step > sw.front().step ? 1 : 0;
      r.switches_before_failure += static_cast<int>(c.owners.switches_dropped);
      continue;
    }
    // The changes around the failure were not kept: who owned the corner then is unknown.
    const bool owner_unknown = gap_at < sw.size() && sw[gap_at - 1].mono_s < failed_mono && sw[gap_at].mono_s >= failed_mono;
    // The owner at the failure, the switches before and after it.
    std::string owner_at_failure = "none";
    const runtime::OwnerSwitch* takeover = nullptr;
    for (std::size_t k = 0; k < sw.size(); ++k) {
      if (sw[k].mono_s < failed_mono) {
        owner_at_failure = sw[k].to;
        if (sw[k].step > sw.front().step) ++r.switches_before_failure;  // not the start's settling
        if (k == gap_at) r.switches_before_failure += static_cast<int>(c.owners.switches_dropped);
        continue;
      }
      ++r.switches_after_failure;
      if (k == gap_at) r.switches_after_failure += static_cast<int>(c.owners.switches_dropped);
      if (sw[k].to == "primary") ++r.switches_back_to_primary;
      if (takeover == nullptr && sw[k].to == "standby") takeover = &sw[k];
    }
    if (owner_unknown) {
      r.takeover_missing += (r.takeover_missing.empty() ? "" : ", ") + c.owners.corner + " (" +
                            std::to_string(c.owners.switches_dropped) + " changes of owner around the failure not kept)";
    } else if (owner_at_failure == "standby") {
      ++r.corners_already_on_standby;
    } else if (takeover != nullptr) {
      takeover_mono = std::max(takeover_mono, takeover->mono_s);
      r.takeover_gap_ms = std::max(r.takeover_gap_ms, takeover->gap_ms);
      takeover_sim = std::max(takeover_sim, takeover->sim_s);
    } else {
      r.takeover_missing += (r.takeover_missing.empty() ? "" : ", ") + c.owners.corner;
    }
    // The dip: how far the tracking error grew beyond its level just before the failure (a
    // corner's standing error, e.g. its calibration's, is not the failover's).
    const ErrorStats before = tracking_error(planner, i, T, c.periods, r.failed_s - kDipReference_s, r.failed_s);
    const ErrorStats after = tracking_error(planner, i, T, c.periods, r.failed_s, r.failed_s + kDipWindow_s);
    if (before.n > 0 && after.n > 0) {
      r.max_force_dip_kN = std::max(r.max_force_dip_kN, after.max_kN - before.mean_kN);
      r.max_tracking_error_before_kN = std::max(r.max_tracking_error_before_kN, std::fabs(before.mean_kN));
    }
  }
  if (failed_mono >= 0.0 && r.takeover_missing.empty()) {
    if (std::isfinite(takeover_mono)) {
      r.takeover_wall_ms = 1e3 * (takeover_mono - failed_mono);
      if (in.lockstep) {
        r.takeover_s = takeover_sim;
        r.takeover_ms = 1e3 * (takeover_sim - r.failed_s);
      } else {
        r.takeover_ms = r.takeover_wall_ms;
        r.takeover_s = r.failed_s + r.takeover_ms / 1e3;
      }
    } else {  // every corner was already on the standby
      r.takeover_s = r.failed_s;
      r.takeover_ms = r.takeover_wall_ms = 0.0;
    }
  }
  return r;
}

void write_failover(json::Writer& j, const FailoverResult& r) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const bool failed = r.failed_s >= 0.0;
  const bool took_over = r.takeover_s >= 0.0;
  j.begin_object("failover")
      .value("failure", r.failure)
      .value("failed_s", failed ? r.failed_s : nan)
      .value("takeover_s", took_over ? r.takeover_s : nan)
      .value("takeover_ms", took_over ? r.takeover_ms : nan)
      .value("takeover_wall_ms", took_over ? r.takeover_wall_ms : nan)
      .value("takeover_missing", r.takeover_missing)
      .value("owners_at_end", r.owners_at_end)
      .value("corners_already_on_standby", r.corners_already_on_standby)
      .value("max_command_gap_ms", r.max_command_gap_ms)
      .value("max_command_gap_wall_ms", r.max_command_gap_wall_ms)
      .value("takeover_gap_ms", r.takeover_gap_ms >= 0.0 ? r.takeover_gap_ms : nan)
      .value("max_force_dip_kN", failed ? r.max_force_dip_kN : nan)
      .value("tracking_error_before_kN", failed ? r.max_tracking_error_before_kN : nan)
      .value("dip_window_s", kDipWindow_s)
      .value("safe_state_entered", r.safe_state_entered)
      .value("safe_state_s", r.safe_state_entered ? r.safe_state_s : nan)
      .value("switches_before_failure", r.switches_before_failure)
      .value("switches_after_failure", r.switches_after_failure)
      .value("switches_back_to_primary", r.switches_back_to_primary)
      .value("commands_stale", r.commands_stale)
      .value("primary_demoted_s", r.demoted_s >= 0.0 ? r.demoted_s : nan)
      .value("primary_demote_reason", r.demote_reason)
      .value("primary_outages", r.primary_outages)
      .value("standby_outages", r.standby_outages)
      .value("primary_stalls", r.primary_stalls)
      .value("standby_stalls", r.standby_stalls)
      .value("standby_failed_s", r.standby_failed_s >= 0.0 ? r.standby_failed_s : nan)
      .end_object();
}

}  // namespace bbw::launch
