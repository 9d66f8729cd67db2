#include "summary.hpp"

#include <cmath>
#include <limits>

namespace bbw::launch {

csv::ReadOptions ccu_log_columns() {
  csv::ReadOptions o;
  // Samples whose estimate is invalid (NaN) are rejected by the reader: they are not scored.
  o.required = {"time_s",  "position_rev", "force_internal_kN", "force_true_kN", "command", "force_mode",
                "estimate_kN", "curve_kN", "fused_kN", "valid", "calibrated"};
  return o;
}

CornerSummary summarize_corner(const std::string& corner, const csv::Table& log) {
  CornerSummary s;
  s.corner = corner;
  const auto& lc = log.column("force_internal_kN");
  const auto& truth = log.column("force_true_kN");
  const auto& cmd = log.column("command");
  const auto& force_mode = log.column("force_mode");
  const auto& est = log.column("estimate_kN");
  const auto& fused = log.column("fused_kN");
  const auto& valid = log.column("valid");
  const auto& calibrated = log.column("calibrated");
  const auto& time = log.column("time_s");
  s.samples = log.rows();
  double fused_sq = 0.0, comp_sq = 0.0, lc_sq = 0.0, track_sq = 0.0, steady_sq = 0.0;
  double held_cmd = 0.0, held_since_s = 0.0;
  for (std::size_t i = 0; i < log.rows(); ++i) {
    if (force_mode[i] > 0.5) {
      const double e = truth[i] - cmd[i];
      track_sq += e * e;
      s.tracking_max_abs_error_kN = std::max(s.tracking_max_abs_error_kN, std::fabs(e));
      ++s.force_samples;
      if (std::fabs(cmd[i] - held_cmd) > 0.05) {
        held_cmd = cmd[i];
        held_since_s = time[i];
      } else if (time[i] - held_since_s >= 0.3 && cmd[i] > 0.5) {
        steady_sq += e * e;
        s.tracking_steady_max_abs_error_kN = std::max(s.tracking_steady_max_abs_error_kN, std::fabs(e));
        ++s.steady_samples;
      }
    }
    if (valid[i] < 0.5 || calibrated[i] < 0.5) continue;
    const double ef = fused[i] - truth[i];
    const double ec = est[i] - truth[i];
    const double el = lc[i] - truth[i];
    fused_sq += ef * ef;
    comp_sq += ec * ec;
    lc_sq += el * el;
    s.fused_max_abs_error_kN = std::max(s.fused_max_abs_error_kN, std::fabs(ef));
    s.compensated_max_abs_error_kN = std::max(s.compensated_max_abs_error_kN, std::fabs(ec));
    ++s.samples_scored;
  }
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  if (s.samples_scored > 0) {
    const double n = static_cast<double>(s.samples_scored);
    s.fused_rms_error_kN = std::sqrt(fused_sq / n);
    s.compensated_rms_error_kN = std::sqrt(comp_sq / n);
    s.load_cell_rms_error_kN = std::sqrt(lc_sq / n);
  } else {
    s.fused_max_abs_error_kN = s.fused_rms_error_kN = kNone;
    s.compensated_max_abs_error_kN = s.compensated_rms_error_kN = kNone;
    s.load_cell_rms_error_kN = kNone;
  }
  if (s.force_samples > 0) {
    s.tracking_rms_error_kN = std::sqrt(track_sq / static_cast<double>(s.force_samples));
  } else {
    s.tracking_max_abs_error_kN = s.tracking_rms_error_kN = kNone;
  }
  if (s.steady_samples > 0) {
    s.tracking_steady_rms_error_kN = std::sqrt(steady_sq / static_cast<double>(s.steady_samples));
  } else {
    s.tracking_steady_max_abs_error_kN = s.tracking_steady_rms_error_kN = kNone;
  }
  return s;
}

std::string not_scored_reason(const CornerSummary& s, long long fits_accepted) {
  if (s.samples_scored > 0) return "";
  if (s.samples == 0) return "the CCU logged no sample of this corner";
  if (fits_accepted <= 0) return "no calibration fit was accepted, so no sample had an estimate to score";
  return "no sample had a valid estimate after the first accepted fit";
}

std::string tracking_not_scored_reason(const CornerSummary& s) {
  if (s.force_samples == 0) return "no sample was under a clamp-force command";
  if (s.steady_samples == 0) return "no hold: no clamp-force command above 0.5 kN stayed within 0.05 kN for 0.3 s";
  return "";
}

}  // namespace bbw::launch

// ---- The complete run's summary.json -------------------------------------------------------

#include <algorithm>
#include <fstream>
#include <iostream>
#include <stdexcept>

#include "bbw/common/json.hpp"
#include "bbw/runtime/run_stats.hpp"
#include "failover_summary.hpp"
#include "fault_report.hpp"
#include "partial_summary.hpp"
#include "report.hpp"

namespace bbw::launch {

std::string incarnation_suffix(unsigned n) {
  if (n == 0) return "";
  std::string s(1, '.');  // built by append: GCC 12 warns (-Wrestrict, a false positive) on "." + string
  s.append(std::to_string(n));
  return s;
}

std::string corner_stats_file(const std::string& out_dir, const std::string& corner, unsigned n) {
  return out_dir + "/corner_" + corner + incarnation_suffix(n) + ".stats";
}

RunTotals write_run_summary(const CompletedRun& run) {
  const scenario::Scenario& scenario = *run.scenario;
  const std::string& out_dir = run.out_dir;
  const std::string& ccu_dir = run.ccu_dir.empty() ? out_dir : run.ccu_dir;
  const std::string ccu_stats_file = ccu_dir + "/ccu.stats";
  const runtime::CcuRunStats ccu = runtime::load_ccu_stats(ccu_stats_file);
  auto incarnations_of = [&](const std::string& c) {
    const auto it = run.incarnations.find(c);
    return it == run.incarnations.end() ? 0u : it->second;
  };
  RunTotals totals;
  totals.simulated_s = ccu.sim_s;
  totals.wall_s = ccu.wall_s;
  json::Writer j;
  std::vector<ReportCorner> report_corners;
  long long overruns = 0, cmd_deadlines = 0, in_flight_total = 0;
  std::map<std::string, double> ccu_lost_s;
  std::vector<std::vector<std::pair<double, double>>> period_logs;
  double max_jitter = 0.0;
  j.begin_object().value("scenario", scenario.name).value("scenario_file", run.scenario_file).value("mode", run.mode);
  j.value("domain", run.domain).value("run_id", run.run_id).value("friction_feedback", run.friction_feedback)
      .value("secure", run.secure);
  j.begin_array("processes_started");  // the scenario's `processes:` (partial summaries: `processes`, how each ended)
  for (const auto& p : run.processes) j.value("", p);
  j.end_array();
  j.value("complete", true).value("interrupted", false);
  // Participants of other bbw runs seen on the domain (by any process of this run).
  std::vector<dds::PeerTag> others;
  {
    std::vector<std::string> files{ccu_stats_file};
    for (const auto& [c, n] : run.incarnations) {
      for (unsigned k = 0; k < n; ++k) files.push_back(corner_stats_file(out_dir, c, k));
    }
    others = foreign_runs_in(files);
  }
  j.begin_array("other_runs_on_domain");
  for (const auto& o : others) {
    j.begin_object().value("run_id", dds::run_id_hex(o.run_id)).value("pid", static_cast<long long>(o.pid))
        .value("process", o.name).end_object();
    std::cerr << "bbw_launch: another bbw run (run id " << dds::run_id_hex(o.run_id) << ", pid " << o.pid << ", "
              << o.name << ") is on domain " << run.domain << "; the run ids kept the two apart\n";
  }
  j.end_array();
  j.begin_array("corners");
  for (const auto& c : scenario.corners) {
    // Counters summed over the corner's incarnations (a restarted process has its own file).
    const unsigned n_inc = incarnations_of(c.name);
    if (n_inc == 0) throw std::runtime_error("corner " + c.name + " was never started");
    std::vector<runtime::CornerRunStats> inc;
    for (unsigned n = 0; n < n_inc; ++n) inc.push_back(runtime::load_corner_stats(corner_stats_file(out_dir, c.name, n)));
    auto corner_sum = [&](auto field) {
      double v = 0.0;
      for (const auto& s : inc) v += static_cast<double>(s.*field);
      return v;
    };
    auto corner_max = [&](auto field) {
      double v = 0.0;
      for (const auto& s : inc) v = std::max(v, static_cast<double>(s.*field));
      return v;
    };
    using CS = runtime::CornerRunStats;
    const runtime::CcuCornerStats& at_ccu = ccu.corner(c.name, ccu_stats_file);
    const auto table = csv::read(ccu_dir + "/ccu_" + c.name + ".csv", ccu_log_columns());
    const auto m = summarize_corner(c.name, table);
    const long long pub = static_cast<long long>(corner_sum(&CS::samples_published));
    // Not receivable: still held back by an injected delay, or sent after the scheduled CCU kill
    // froze the CCU (counted by the corner from the schedule, never from its watchdog's guess).
    const long long in_flight =
        static_cast<long long>(corner_sum(&CS::samples_in_flight) + corner_sum(&CS::samples_without_ccu));
    const long long rec = static_cast<long long>(at_ccu.samples_received);
    // Measurement samples missing at the CCU, measurement block numbers skipped, and commands
    // the corner never saw (realtime: a corner follows the newest, so only the first matters
    // for "no sample lost"); sequence_gaps is their sum.
    const long long sample_gaps = static_cast<long long>(at_ccu.sample_gaps);
    const long long block_gaps = static_cast<long long>(at_ccu.block_gaps);
    const long long command_gaps = static_cast<long long>(corner_sum(&CS::command_seq_gaps));
    const long long g = sample_gaps + block_gaps + command_gaps;
    totals.published += pub;
    in_flight_total += in_flight;
    totals.received += rec;
    totals.gaps += g;
    overruns += static_cast<long long>(corner_sum(&CS::overruns));
    cmd_deadlines += static_cast<long long>(corner_sum(&CS::command_deadlines_missed));
    max_jitter = std::max(max_jitter, corner_max(&CS::max_jitter_s));
    ccu_lost_s[c.name] = inc.back().ccu_lost_s;
    std::vector<std::pair<double, double>> period_rows;
    {
      csv::ReadOptions o;
      o.required = {"time_s", "force_true_kN"};
      const auto t = csv::read(out_dir + "/corner_" + c.name + "_periods.csv", o);
      for (std::size_t r = 0; r < t.rows(); ++r) period_rows.emplace_back(t.column("time_s")[r], t.column("force_true_kN")[r]);
    }
    period_logs.push_back(std::move(period_rows));
    const long long fits_accepted = static_cast<long long>(at_ccu.fits_accepted);
    j.begin_object()
        .value("corner", c.name)
        .value("temperature_C", c.conditions.temperature_C)
        .value("estimate_max_abs_error_kN", m.fused_max_abs_error_kN)
        .value("estimate_rms_error_kN", m.fused_rms_error_kN)
        .value("compensated_load_cell_max_abs_error_kN", m.compensated_max_abs_error_kN)
        .value("compensated_load_cell_rms_error_kN", m.compensated_rms_error_kN)
        .value("raw_load_cell_rms_error_kN", m.load_cell_rms_error_kN)
        .value("samples_scored", m.samples_scored)
        .value("force_command_samples", m.force_samples)
        .value("tracking_max_abs_error_kN", m.tracking_max_abs_error_kN)
        .value("tracking_rms_error_kN", m.tracking_rms_error_kN)
        .value("tracking_steady_max_abs_error_kN", m.tracking_steady_max_abs_error_kN)
        .value("tracking_steady_rms_error_kN", m.tracking_steady_rms_error_kN);
    // Errors over no sample are null, with the reason (null when scored).
    auto reason_or_null = [&](const std::string& key, const std::string& why) {
      if (why.empty()) j.value(key, std::numeric_limits<double>::quiet_NaN());
      else j.value(key, why);
    };
    reason_or_null("not_scored_reason", not_scored_reason(m, fits_accepted));
    reason_or_null("tracking_not_scored_reason", tracking_not_scored_reason(m));
    j.value("fits_accepted", fits_accepted)
        .value("fits_rejected", static_cast<long long>(at_ccu.fits_rejected))
        .value("first_fit_time_s", at_ccu.first_fit_time_s)
        .value("samples_published", pub)
        .value("samples_received", rec)
        .value("sequence_gaps", g)
        .value("sample_gaps", sample_gaps)
        .value("block_gaps", block_gaps)
        .value("command_gaps", command_gaps)
        .value("samples_suppressed_by_fault", static_cast<long long>(corner_sum(&CS::samples_suppressed)))
        .value("samples_not_receivable", in_flight)
        .value("incarnations", static_cast<long long>(n_inc))
        .value("rejoins", static_cast<long long>(at_ccu.rejoins))
        .value("samples_rejected_by_guard", static_cast<long long>(at_ccu.guard_rejected))
        .value("calibrator_restarts", static_cast<long long>(at_ccu.calibrator_restarts))
        .value("measurement_deadline_misses", static_cast<long long>(at_ccu.deadlines_missed))
        .value("measurement_liveliness_lost", static_cast<long long>(at_ccu.liveliness_lost))
        .value("command_deadline_misses", static_cast<long long>(corner_sum(&CS::command_deadlines_missed)))
        .value("ccu_lost_detected_s", ccu_lost_s[c.name])
        .value("max_jitter_s", corner_max(&CS::max_jitter_s))
        .value("mean_jitter_s", inc.front().mean_jitter_s)
        .value("overruns", static_cast<long long>(corner_sum(&CS::overruns)))
        .value("commands_clamped", static_cast<long long>(corner_sum(&CS::commands_clamped)))
        .value("commands_refused_run", static_cast<long long>(corner_sum(&CS::commands_refused_run)))
        .value("commands_refused_source", static_cast<long long>(corner_sum(&CS::commands_refused_source)))
        .value("commands_refused_value", static_cast<long long>(corner_sum(&CS::commands_refused_value)))
        .end_object();
    ReportCorner rc;
    rc.summary = m;
    rc.calibrated = at_ccu.fits_accepted > 0;
    rc.curve = {at_ccu.curve_a, at_ccu.curve_b, at_ccu.curve_c, at_ccu.curve_d};
    report_corners.push_back(rc);
  }
  j.end_array();
  const double sim_s = ccu.sim_s, wall_s = ccu.wall_s;
  j.begin_object("run")
      .value("mode", run.mode)
      .value("simulated_s", sim_s)
      .value("wall_s", wall_s)
      .value("launch_wall_s", run.launch_wall_s)
      .value("real_time_factor", wall_s > 0.0 ? sim_s / wall_s : 0.0)
      .value("samples_published", totals.published)
      .value("samples_received", totals.received)
      .value("samples_lost", totals.published - totals.received - in_flight_total)
      .value("ended_by_injected_ccu_kill", run.ended_by_injected_ccu_kill)
      .value("sequence_gaps", totals.gaps)
      .value("measurement_deadline_misses", static_cast<long long>(ccu.measurement_deadlines_missed))
      .value("measurement_liveliness_lost", static_cast<long long>(ccu.measurement_liveliness_lost))
      .value("command_deadline_misses", cmd_deadlines)
      .value("max_jitter_s", max_jitter)
      .value("overruns", overruns)
      .value("foreign_run_samples", static_cast<long long>(ccu.foreign_run_samples))
      .end_object();
  // Injected faults against what was detected, and the total clamp force against demand.
  const auto timeline = build_timeline(scenario, period_logs);
  const std::vector<Detection>& detections = ccu.detections;
  const auto faults = assess_faults(*run.schedule, detections, ccu_lost_s, timeline, scenario.duration_s);
  j.begin_array("faults");
  for (const auto& f : faults) {
    j.begin_object()
        .value("corner", std::string(faults::to_string(f.fault.target)))
        .value("part", std::string(faults::to_string(f.fault.part)))
        .value("type", std::string(faults::to_string(f.fault.type)))
        .value("injected_s", f.fault.at_s)
        .value("ends_s", std::min(f.fault.end_s(), scenario.duration_s))
        .value("masked", f.masked)
        .value("observable_s", f.observable_s)
        .value("detected", f.detected)
        .value("detected_s", f.detected ? f.detected_s : -1.0)
        .value("latency_ms", f.detected ? f.latency_ms : -1.0)
        .value("diagnosis", faults::diagnosis_name(f))
        .value("diagnosis_s", f.detected ? f.diagnosis_s : -1.0)
        .value("diagnosis_latency_ms", f.detected ? f.diagnosis_latency_ms : -1.0)
        .value("correct", f.correct)
        .value("reaction", std::string(f.reaction))
        .value("delivered_share", f.delivered_share)
        .end_object();
  }
  j.end_array();
  // Detections no injected fault explains (the one scorer, bbw/faults/outcome.hpp).
  j.begin_array("false_alarms");
  for (const auto& d : false_alarms(*run.schedule, detections)) {
    j.begin_object()
        .value("corner", std::string(faults::to_string(d.corner)))
        .value("finding", std::string(faults::to_string(d.finding)))
        .value("onset_s", d.onset_s)
        .value("detected_s", d.detected_s)
        .end_object();
  }
  j.end_array();
  j.begin_array("detections");
  for (const auto& d : detections) {
    j.begin_object()
        .value("corner", d.corner)
        .value("part", d.part)
        .value("finding", d.finding)
        .value("onset_s", d.onset_s)
        .value("detected_s", d.detected_s)
        .end_object();
  }
  j.end_array();
  if (run.standby) {
    write_failover(j, assess_failover(load_failover_input(scenario, out_dir, run.mode == "lockstep")));
  }
  j.end_object();
  j.save(out_dir + "/summary.json");
  {
    std::ofstream tl(out_dir + "/timeline.csv");
    tl << "time_s,demand_total_kN,delivered_total_kN\n";
    for (const auto& p : timeline) tl << p.time_s << ',' << p.demand_kN << ',' << p.delivered_kN << '\n';
    if (!tl) throw std::runtime_error(out_dir + "/timeline.csv: cannot write");
  }
  if (run.report) {
    write_report(out_dir, "bbw run: " + scenario.name + " (" + run.mode + ")", report_corners, j.str(), &faults,
                 &detections);
  }
  return totals;
}

}  // namespace bbw::launch
