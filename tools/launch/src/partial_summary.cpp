#include "partial_summary.hpp"

#include <signal.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "bbw/common/json.hpp"
#include "bbw/launch/stats_file.hpp"
#include "summary.hpp"

namespace bbw::launch {

namespace {

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

// The stats of a process, or empty when it left none (killed before writing them).
std::map<std::string, std::string> stats_or_empty(const std::string& file) {
  try {
    return read_stats(file);
  } catch (const std::exception&) {
    return {};
  }
}

double number_or_none(const std::map<std::string, std::string>& m, const std::string& key) {
  try {
    return stat_number(m, key, "");
  } catch (const std::exception&) {
    return kNone;
  }
}

std::string corner_stats_file(const std::string& out, const std::string& c, unsigned n) {
  return out + "/corner_" + c + (n == 0 ? "" : "." + std::to_string(n)) + ".stats";
}

}  // namespace

std::vector<std::string> lost_processes(const PartialRun& run) {
  std::vector<std::string> lost;
  for (const auto& p : run.processes) {
    if (!p.ended_by_itself || p.ok || p.scheduled_kill) continue;
    if (run.interrupted && (p.exit_code == 128 + SIGINT || p.exit_code == 128 + SIGTERM)) continue;
    lost.push_back(p.name);
  }
  return lost;
}

std::vector<dds::PeerTag> foreign_runs_in(const std::vector<std::string>& stats_files) {
  std::vector<dds::PeerTag> out;
  for (const auto& f : stats_files) {
    const auto m = stats_or_empty(f);
    const auto it = m.find("foreign_runs");
    if (it == m.end()) continue;
    for (const auto& t : dds::split_peer_tags(it->second)) {
      bool seen = false;
      for (const auto& o : out) seen = seen || (o.run_id == t.run_id && o.pid == t.pid);
      if (!seen) out.push_back(t);
    }
  }
  return out;
}

std::vector<std::string> write_partial_summary(const PartialRun& run) {
  const std::vector<std::string> lost = lost_processes(run);
  const std::string ccu_file = run.out_dir + "/ccu.stats";
  const auto ccu = stats_or_empty(ccu_file);
  json::Writer j;
  j.begin_object()
      .value("scenario", run.scenario->name)
      .value("scenario_file", run.scenario_file)
      .value("mode", run.mode)
      .value("domain", run.domain)
      .value("run_id", run.run_id)
      .value("secure", run.secure)
      .value("complete", false)
      .value("interrupted", run.interrupted)
      .value("signal", run.interrupted ? std::string(run.signal == SIGINT ? "SIGINT" : "SIGTERM") : std::string(""))
      .value("failure", run.failure);
  j.begin_array("lost_processes");
  for (const auto& name : lost) j.begin_object().value("process", name).end_object();
  j.end_array();
  j.begin_array("processes");
  for (const auto& p : run.processes) {
    j.begin_object()
        .value("process", p.name)
        .value("ended", p.ended_by_itself ? "by itself" : "stopped by the launcher")
        .value("status", p.status)
        .end_object();
  }
  j.end_array();
  std::vector<std::string> stats_files{ccu_file};
  j.begin_array("corners");
  for (const auto& c : run.scenario->corners) {
    const auto it = run.incarnations.find(c.name);
    const unsigned n = it == run.incarnations.end() ? 0 : it->second;
    double periods = 0.0, published = 0.0, refused = 0.0, clamped = 0.0, applied = 0.0;
    unsigned with_stats = 0;
    for (unsigned k = 0; k < n; ++k) {
      const std::string f = corner_stats_file(run.out_dir, c.name, k);
      stats_files.push_back(f);
      const auto m = stats_or_empty(f);
      if (m.empty()) continue;
      ++with_stats;
      periods += number_or_none(m, "periods");
      published += number_or_none(m, "samples_published");
      applied += number_or_none(m, "commands_applied");
      clamped += number_or_none(m, "commands_clamped");
      refused += number_or_none(m, "commands_refused_run") + number_or_none(m, "commands_refused_source") +
                 number_or_none(m, "commands_refused_value");
    }
    const bool have = with_stats > 0;
    const std::string p = c.name + ".";
    j.begin_object()
        .value("corner", c.name)
        .value("stats_logged", have)
        .value("periods", have ? periods : kNone)
        .value("samples_published", have ? published : kNone)
        .value("commands_applied", have ? applied : kNone)
        .value("commands_clamped", have ? clamped : kNone)
        .value("commands_refused", have ? refused : kNone)
        .value("samples_received", number_or_none(ccu, p + "samples_received"))
        .value("sample_gaps", number_or_none(ccu, p + "sample_gaps"));
    // The CCU's per-sample log as far as it was written (a killed CCU may leave a cut line).
    const std::string log = run.out_dir + "/ccu_" + c.name + ".csv";
    std::string log_state = "missing";
    double max_err = kNone, scored = kNone;
    if (std::filesystem::exists(log)) {
      try {
        const CornerSummary s = summarize_corner(c.name, csv::read(log, ccu_log_columns()));
        scored = static_cast<double>(s.samples_scored);
        if (s.samples_scored > 0) max_err = s.fused_max_abs_error_kN;
        log_state = "read";
      } catch (const std::exception& e) {
        log_state = std::string("unreadable: ") + e.what();
      }
    }
    j.value("ccu_log", log_state).value("samples_scored", scored).value("estimate_max_abs_error_kN", max_err);
    j.end_object();
  }
  j.end_array();
  j.begin_array("other_runs_on_domain");
  for (const auto& o : foreign_runs_in(stats_files)) {
    j.begin_object().value("run_id", dds::run_id_hex(o.run_id)).value("pid", static_cast<long long>(o.pid))
        .value("process", o.name).end_object();
  }
  j.end_array();
  j.value("ccu_stats_logged", !ccu.empty());
  j.end_object();
  j.save(run.out_dir + "/summary.json");
  return lost;
}

}  // namespace bbw::launch
