#include "partial_summary.hpp"

#include <signal.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>

#include "bbw/common/json.hpp"
#include "bbw/runtime/run_stats.hpp"
#include "summary.hpp"

namespace bbw::launch {

namespace {

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

// The stats of a process, or none when it left none (killed before writing them) or they do
// not parse (a cut file).
std::optional<runtime::CcuRunStats> ccu_stats_or_none(const std::string& file) {
  try {
    return runtime::load_ccu_stats(file);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::optional<runtime::CornerRunStats> corner_stats_or_none(const std::string& file) {
  try {
    return runtime::load_corner_stats(file);
  } catch (const std::exception&) {
    return std::nullopt;
  }
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
    // Either kind of stats file: the CCU's, or a corner's.
    std::string tags;
    if (const auto c = ccu_stats_or_none(f)) tags = c->foreign_runs;
    else if (const auto k = corner_stats_or_none(f)) tags = k->foreign_runs;
    else continue;
    for (const auto& t : dds::split_peer_tags(tags)) {
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
  const auto ccu = ccu_stats_or_none(ccu_file);
  // The CCU's entry of a corner, when it logged one.
  auto ccu_corner = [&](const std::string& name) -> const runtime::CcuCornerStats* {
    if (!ccu) return nullptr;
    for (const auto& c : ccu->corners) {
      if (c.corner == name) return &c;
    }
    return nullptr;
  };
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
      const auto m = corner_stats_or_none(f);
      if (!m) continue;
      ++with_stats;
      periods += static_cast<double>(m->periods);
      published += static_cast<double>(m->samples_published);
      applied += static_cast<double>(m->commands_applied);
      clamped += static_cast<double>(m->commands_clamped);
      refused += static_cast<double>(m->commands_refused_run + m->commands_refused_source + m->commands_refused_value);
    }
    const bool have = with_stats > 0;
    const runtime::CcuCornerStats* at_ccu = ccu_corner(c.name);
    j.begin_object()
        .value("corner", c.name)
        .value("stats_logged", have)
        .value("periods", have ? periods : kNone)
        .value("samples_published", have ? published : kNone)
        .value("commands_applied", have ? applied : kNone)
        .value("commands_clamped", have ? clamped : kNone)
        .value("commands_refused", have ? refused : kNone)
        .value("samples_received", at_ccu ? static_cast<double>(at_ccu->samples_received) : kNone)
        .value("sample_gaps", at_ccu ? static_cast<double>(at_ccu->sample_gaps) : kNone);
    // The CCU's per-sample log as far as it was written (a killed CCU may leave a cut line).
    const std::string log = run.out_dir + "/ccu_" + c.name + ".csv";
    std::string log_state = "missing";
    double max_err = kNone, scored = kNone;
    std::string why = "the CCU's log of this corner is " + log_state;
    if (std::filesystem::exists(log)) {
      try {
        const CornerSummary s = summarize_corner(c.name, csv::read(log, ccu_log_columns()));
        scored = static_cast<double>(s.samples_scored);
        max_err = s.fused_max_abs_error_kN;  // NaN (null) when nothing was scored
        why = not_scored_reason(s, at_ccu ? static_cast<long long>(at_ccu->fits_accepted) : 1);
        log_state = "read";
      } catch (const std::exception& e) {
        log_state = std::string("unreadable: ") + e.what();
        why = "the CCU's log of this corner is " + log_state;
      }
    }
    j.value("ccu_log", log_state).value("samples_scored", scored).value("estimate_max_abs_error_kN", max_err);
    if (why.empty()) j.value("not_scored_reason", kNone);
    else j.value("not_scored_reason", why);
    j.end_object();
  }
  j.end_array();
  j.begin_array("other_runs_on_domain");
  for (const auto& o : foreign_runs_in(stats_files)) {
    j.begin_object().value("run_id", dds::run_id_hex(o.run_id)).value("pid", static_cast<long long>(o.pid))
        .value("process", o.name).end_object();
  }
  j.end_array();
  j.value("ccu_stats_logged", ccu.has_value());
  j.end_object();
  j.save(run.out_dir + "/summary.json");
  return lost;
}

}  // namespace bbw::launch
