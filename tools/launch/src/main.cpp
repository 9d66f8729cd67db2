// bbw_launch (./bbw run): the CCU and one process per corner over Fast DDS on this host.
//
//   bbw_launch SCENARIO.yaml --out DIR [--mode lockstep|realtime] [--domain N]
//              [--discovery-timeout S] [--friction-feedback on|off] [--no-report]
//
// Starts bbw_ccu and bbw_corner (one per scenario corner) as separate processes with their
// output in DIR/<name>.out/.err, waits for them to finish within a bounded wall time, and
// writes DIR/summary.json and DIR/report.html. If a process dies or fails (discovery timeout,
// lost peer), the others are stopped and the launcher exits non-zero naming the process and
// the reason. Exit: 0 ok, 1 a process failed or the run exceeded its bound, 2 bad arguments.
#include <signal.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bbw/common/json.hpp"
#include "bbw/dds/domain.hpp"
#include "bbw/dds/shm_cleanup.hpp"
#include "bbw/launch/child.hpp"
#include "bbw/launch/signals.hpp"
#include "bbw/launch/stats_file.hpp"
#include "bbw/scenario/load.hpp"
#include "report.hpp"
#include "summary.hpp"

namespace {

using namespace std::chrono_literals;
using bbw::launch::Child;
using bbw::launch::Clock;

const char* kUsage =
    "usage: bbw_launch SCENARIO.yaml --out DIR [--mode lockstep|realtime] [--domain N]\n"
    "                  [--discovery-timeout S] [--friction-feedback on|off] [--no-report]\n";

std::string last_line(const std::string& file) {
  std::ifstream f(file);
  std::string line, last;
  while (std::getline(f, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

std::string reason(const bbw::launch::ExitStatus& s) {
  if (!s.exited) return s.describe();
  switch (s.code) {
    case 1: return "exit 1 (runtime or DDS error)";
    case 2: return "exit 2 (bad arguments or configuration)";
    case 3: return "exit 3 (discovery did not complete in time)";
    case 4: return "exit 4 (peer lost or failed)";
    case 127: return "exit 127 (could not be executed)";
    default: return s.describe();
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::unique_ptr<Child>> children;
  std::atomic<bool> interrupted{false};
  bbw::launch::SignalWatcher signals([&](int) { interrupted.store(true); });

  std::string scenario_file, out_dir, mode = "lockstep", feedback = "on";
  std::optional<std::string> domain_arg;
  double discovery_s = 20.0;
  bool report = true;
  int domain = 0;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string k = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument("missing value after " + k);
        return argv[++i];
      };
      if (k == "--out") out_dir = next();
      else if (k == "--mode") mode = next();
      else if (k == "--domain") domain_arg = next();
      else if (k == "--discovery-timeout") {
        const std::string v = next();
        char* end = nullptr;
        discovery_s = std::strtod(v.c_str(), &end);
        if (v.empty() || *end != '\0' || !(discovery_s > 0.0 && discovery_s <= 600.0)) {
          throw std::invalid_argument("--discovery-timeout must be seconds in (0, 600], got '" + v + "'");
        }
      } else if (k == "--friction-feedback") feedback = next();
      else if (k == "--no-report") report = false;
      else if (k == "-h" || k == "--help") { std::cout << kUsage; return 0; }
      else if (!k.empty() && k[0] == '-') throw std::invalid_argument("unknown argument '" + k + "'");
      else if (scenario_file.empty()) scenario_file = k;
      else throw std::invalid_argument("unexpected argument '" + k + "'");
    }
    if (scenario_file.empty()) throw std::invalid_argument("a scenario file is required");
    if (out_dir.empty()) throw std::invalid_argument("--out DIR is required");
    if (mode != "lockstep" && mode != "realtime") throw std::invalid_argument("--mode must be lockstep or realtime, got '" + mode + "'");
    if (feedback != "on" && feedback != "off") throw std::invalid_argument("--friction-feedback must be on or off");
    domain = bbw::dds::resolve_domain_id(domain_arg, std::getenv("BBW_DOMAIN"));
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: " << e.what() << "\n" << kUsage;
    return 2;
  }

  // Validate the scenario before starting anything.
  std::optional<bbw::scenario::Scenario> scenario;
  try {
    scenario = bbw::scenario::load_scenario(scenario_file);
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: " << e.what() << "\n";
    return 2;
  }
  ::mkdir(out_dir.c_str(), 0755);
  struct stat st {};
  if (::stat(out_dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    std::cerr << "bbw_launch: cannot create output directory " << out_dir << "\n";
    return 2;
  }
  const auto shm = bbw::dds::cleanup_stale_shm();
  if (!shm.removed.empty()) {
    std::cout << "bbw_launch: removed " << shm.removed.size() << " stale Fast DDS shared-memory files" << std::endl;
  }

  const std::string bin = bbw::launch::executable_dir();
  // Test hook: BBW_LAUNCH_CORNER_BIN replaces the corner executable (e.g. one that fails to
  // start), so the failure path is exercised with real processes.
  const char* corner_bin_env = std::getenv("BBW_LAUNCH_CORNER_BIN");
  const std::string corner_bin = corner_bin_env && *corner_bin_env ? corner_bin_env : bin + "/bbw_corner";
  const std::string dom = std::to_string(domain);
  const std::string disc = std::to_string(discovery_s);
  const auto wall0 = Clock::now();
  try {
    children.push_back(std::make_unique<Child>(
        "bbw_ccu",
        std::vector<std::string>{bin + "/bbw_ccu", "--scenario", scenario_file, "--domain", dom, "--mode", mode,
                                 "--out", out_dir, "--discovery-timeout", disc, "--friction-feedback", feedback},
        out_dir + "/ccu.out", out_dir + "/ccu.err"));
    for (const auto& c : scenario->corners) {
      children.push_back(std::make_unique<Child>(
          "bbw_corner " + c.name,
          std::vector<std::string>{corner_bin, "--corner", c.name, "--scenario", scenario_file, "--domain",
                                   dom, "--mode", mode, "--stats", out_dir + "/corner_" + c.name + ".stats",
                                   "--discovery-timeout", disc},
          out_dir + "/corner_" + c.name + ".out", out_dir + "/corner_" + c.name + ".err"));
    }
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: " << e.what() << "\n";
    for (auto& c : children) c->stop(2000ms);
    return 1;
  }
  std::cout << "bbw_launch: " << scenario->name << ", " << mode << ", domain " << domain << ", "
            << children.size() << " processes, discovery deadline " << discovery_s << " s" << std::endl;

  // Bound on the whole run: discovery plus a generous multiple of the simulated duration.
  const double bound_s = discovery_s + (mode == "lockstep" ? 10.0 * scenario->duration_s + 60.0
                                                           : 1.5 * scenario->duration_s + 20.0);
  const auto deadline = wall0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(bound_s));
  std::vector<Child*> raw;
  for (auto& c : children) raw.push_back(c.get());
  std::string failure;
  std::size_t finished = 0;
  while (finished < raw.size()) {
    // Wake at least every 200 ms to notice SIGINT/SIGTERM (the children get it from the
    // terminal's process group too; this only bounds how long we take to stop them).
    const auto wake = std::min(deadline, Clock::now() + 200ms);
    const int i = bbw::launch::wait_any(raw, wake);
    if (interrupted.load()) {
      failure = "interrupted by signal";
      break;
    }
    if (i < 0) {
      if (Clock::now() >= deadline) {
        failure = "run exceeded its wall-time bound of " + std::to_string(static_cast<int>(bound_s)) + " s";
        break;
      }
      continue;
    }
    ++finished;
    const auto status = *raw[static_cast<std::size_t>(i)]->status();
    if (!status.ok()) {
      const std::string name = raw[static_cast<std::size_t>(i)]->name();
      std::string err_file = out_dir + (name == "bbw_ccu" ? "/ccu.err" : "/corner_" + name.substr(11) + ".err");
      failure = name + " failed: " + reason(status);
      const std::string msg = last_line(err_file);
      if (!msg.empty()) failure += ": " + msg;
      break;
    }
  }
  if (!failure.empty()) {
    for (auto& c : children) c->stop(3000ms);
    std::cerr << "bbw_launch: " << failure << " (logs in " << out_dir << ")\n";
    return 1;
  }
  const double launch_wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();

  // Summary.
  try {
    const std::string ccu_stats_file = out_dir + "/ccu.stats";
    const auto ccu = bbw::launch::read_stats(ccu_stats_file);
    auto num = [&](const std::map<std::string, std::string>& m, const std::string& k, const std::string& f) {
      return bbw::launch::stat_number(m, k, f);
    };
    const double sim_s = num(ccu, "sim_s", ccu_stats_file);
    const double wall_s = num(ccu, "wall_s", ccu_stats_file);
    bbw::json::Writer j;
    std::vector<bbw::launch::ReportCorner> report_corners;
    long long published = 0, received = 0, gaps = 0, overruns = 0, cmd_deadlines = 0;
    double max_jitter = 0.0;
    j.begin_object().value("scenario", scenario->name).value("scenario_file", scenario_file).value("mode", mode);
    j.value("domain", domain).value("friction_feedback", feedback);
    j.begin_array("corners");
    for (const auto& c : scenario->corners) {
      const std::string cs_file = out_dir + "/corner_" + c.name + ".stats";
      const auto cs = bbw::launch::read_stats(cs_file);
      const auto table = bbw::csv::read(out_dir + "/ccu_" + c.name + ".csv", bbw::launch::ccu_log_columns());
      const auto m = bbw::launch::summarize_corner(c.name, table);
      const std::string p = c.name + ".";
      const long long pub = static_cast<long long>(num(cs, "samples_published", cs_file));
      const long long rec = static_cast<long long>(num(ccu, p + "samples_received", ccu_stats_file));
      const long long g = static_cast<long long>(num(ccu, p + "sample_gaps", ccu_stats_file) +
                                                 num(ccu, p + "block_gaps", ccu_stats_file) +
                                                 num(cs, "command_seq_gaps", cs_file));
      published += pub;
      received += rec;
      gaps += g;
      overruns += static_cast<long long>(num(cs, "overruns", cs_file));
      cmd_deadlines += static_cast<long long>(num(cs, "command_deadlines_missed", cs_file));
      max_jitter = std::max(max_jitter, num(cs, "max_jitter_s", cs_file));
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
          .value("fits_accepted", static_cast<long long>(num(ccu, p + "fits_accepted", ccu_stats_file)))
          .value("fits_rejected", static_cast<long long>(num(ccu, p + "fits_rejected", ccu_stats_file)))
          .value("first_fit_time_s", num(ccu, p + "first_fit_time_s", ccu_stats_file))
          .value("samples_published", pub)
          .value("samples_received", rec)
          .value("sequence_gaps", g)
          .value("max_jitter_s", num(cs, "max_jitter_s", cs_file))
          .value("mean_jitter_s", num(cs, "mean_jitter_s", cs_file))
          .value("overruns", static_cast<long long>(num(cs, "overruns", cs_file)))
          .end_object();
      bbw::launch::ReportCorner rc;
      rc.summary = m;
      rc.calibrated = num(ccu, p + "fits_accepted", ccu_stats_file) > 0;
      rc.curve = {num(ccu, p + "curve_a", ccu_stats_file), num(ccu, p + "curve_b", ccu_stats_file),
                  num(ccu, p + "curve_c", ccu_stats_file), num(ccu, p + "curve_d", ccu_stats_file)};
      report_corners.push_back(rc);
    }
    j.end_array();
    j.begin_object("run")
        .value("mode", mode)
        .value("simulated_s", sim_s)
        .value("wall_s", wall_s)
        .value("launch_wall_s", launch_wall_s)
        .value("real_time_factor", wall_s > 0.0 ? sim_s / wall_s : 0.0)
        .value("samples_published", published)
        .value("samples_received", received)
        .value("samples_lost", published - received)
        .value("sequence_gaps", gaps)
        .value("measurement_deadline_misses", static_cast<long long>(num(ccu, "measurement_deadlines_missed", ccu_stats_file)))
        .value("measurement_liveliness_lost", static_cast<long long>(num(ccu, "measurement_liveliness_lost", ccu_stats_file)))
        .value("command_deadline_misses", cmd_deadlines)
        .value("max_jitter_s", max_jitter)
        .value("overruns", overruns)
        .end_object();
    j.end_object();
    j.save(out_dir + "/summary.json");
    if (report) bbw::launch::write_report(out_dir, "bbw run: " + scenario->name + " (" + mode + ")", report_corners, j.str());
    std::cout << "bbw_launch: done: simulated " << sim_s << " s in " << wall_s << " s (real-time factor "
              << (wall_s > 0 ? sim_s / wall_s : 0.0) << "), samples published " << published << ", received "
              << received << ", gaps " << gaps << "; " << out_dir << "/summary.json" << std::endl;
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: summary failed: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
