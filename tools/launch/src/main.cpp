// bbw_launch (./bbw run): the CCU and one process per corner over Fast DDS on this host.
//
//   bbw_launch SCENARIO.yaml --out DIR [--mode lockstep|realtime] [--domain N]
//              [--discovery-timeout S] [--friction-feedback on|off] [--no-report]
//              [--secure [--keys DIR]]
//
// --secure: DDS Security (docs/security.md) with the keys in DIR (default keys/ in the
// repository, gitignored); when a file is missing scripts/bbw-keys.sh DIR creates it (output in
// OUT/keys.out/.err), then every child gets --secure DIR.
//
// Starts bbw_ccu and bbw_corner (one per scenario corner) as separate processes with their
// output in DIR/<name>.out/.err, waits for them to finish within a bounded wall time, and
// writes DIR/summary.json and DIR/report.html. If a process dies or fails (discovery timeout,
// lost peer), the others are stopped and the launcher exits non-zero naming the process and
// the reason, after a partial summary from what the processes logged (partial_summary.hpp).
// SIGINT/SIGTERM stop the run the same way, with a partial summary marked interrupted.
// Exit: 0 ok, 1 a process failed or the run exceeded its bound, 2 bad arguments, 130/143
// stopped by SIGINT/SIGTERM.
//
// Each run draws a random run id (/dev/urandom) that every child gets as --run-id: its DDS
// partitions and messages carry it, so runs on one domain never mix (docs/distributed.md,
// "Runs on one host"). Without --domain and BBW_DOMAIN a free domain is chosen
// (domain_claim.hpp). DIR is created, or cleared of an older run's files, or refused when it
// holds files bbw did not write (out_dir.hpp).
//
// Process faults of the scenario's schedule (docs/faults.md) are carried out here: a process
// freezes itself (SIGSTOP) at its scheduled kill time (lockstep: the period; realtime: its wall
// clock), the launcher SIGKILLs it at once and, if asked, starts a new incarnation of a corner
// (lockstep: at once, the CCU holds the clock at the restart period until it has joined;
// realtime: restart_after_s of wall time later). A scheduled kill is not a failure: after a CCU
// kill the corners run to the end in their safe state and the run is reported as ended by the
// injected fault. Any other death is an error naming the process.
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "bbw/common/json.hpp"
#include "bbw/dds/domain.hpp"
#include "bbw/dds/process_cli.hpp"
#include "bbw/dds/run_id.hpp"
#include "bbw/dds/shm_cleanup.hpp"
#include "bbw/faults/link_faults.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/common/data_path.hpp"
#include "bbw/launch/child.hpp"
#include "bbw/launch/signals.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/scenario/run_checks.hpp"
#include "bbw/security/dds_security.hpp"
#include "domain_claim.hpp"
#include "fault_report.hpp"
#include "out_dir.hpp"
#include "partial_summary.hpp"
#include "report.hpp"
#include "summary.hpp"

namespace {

using namespace std::chrono_literals;
using bbw::launch::Child;
using bbw::launch::Clock;

const char* kUsage =
    "usage: bbw_launch SCENARIO.yaml --out DIR [--mode lockstep|realtime] [--domain N]\n"
    "                  [--discovery-timeout S] [--friction-feedback on|off] [--no-report]\n"
    "                  [--secure [--keys DIR]] [--allow-large]\n";

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
  std::atomic<int> stop_signal{0};
  bbw::launch::SignalWatcher signals([&](int sig) {
    stop_signal.store(sig);
    interrupted.store(true);
  });

  std::string scenario_file, out_dir, mode = "lockstep", feedback = "on";
  std::optional<std::string> domain_arg;
  double discovery_s = 20.0;
  bool report = true;
  bool secure = false;
  bool allow_large = false;  // --allow-large: accept a run over the size limits (scenario/run_checks.hpp)
  std::string keys_dir;  // default: keys/ in bbw's data root (bbw/common/data_path.hpp)
  int domain = 0;
  try {
    for (bbw::dds::ArgCursor args(argc, argv); !args.done();) {
      const std::string k = args.flag();
      auto next = [&] { return args.value(); };
      if (k == "--out") out_dir = next();
      else if (k == "--mode") bbw::dds::parse_clock_mode(mode = next());
      else if (k == "--domain") domain_arg = next();
      else if (k == "--discovery-timeout") {
        discovery_s = static_cast<double>(bbw::dds::seconds_arg(k, next(), 600.0).count()) / 1000.0;
      } else if (k == "--friction-feedback") feedback = next();
      else if (k == "--no-report") report = false;
      else if (k == "--secure") secure = true;
      else if (k == "--keys") keys_dir = next();
      else if (k == "--allow-large") allow_large = true;
      else if (k == "-h" || k == "--help") { std::cout << kUsage; return 0; }
      else if (!k.empty() && k[0] == '-') throw std::invalid_argument("unknown argument '" + k + "'");
      else if (scenario_file.empty()) scenario_file = k;
      else throw std::invalid_argument("unexpected argument '" + k + "'");
    }
    if (scenario_file.empty()) throw std::invalid_argument("a scenario file is required");
    if (out_dir.empty()) throw std::invalid_argument("--out DIR is required");
    if (feedback != "on" && feedback != "off") throw std::invalid_argument("--friction-feedback must be on or off");
    domain = bbw::dds::resolve_domain_id(domain_arg, std::getenv("BBW_DOMAIN"), -1);
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: " << e.what() << "\n" << kUsage;
    return 2;
  }
  // The run id (never the scenario seed): every child gets it, every endpoint lives in
  // partitions derived from it, every message carries it (bbw/dds/run_id.hpp).
  std::uint64_t run_id = 0;
  bbw::launch::DomainClaim domain_claim;
  try {
    run_id = bbw::dds::random_run_id();
    if (domain < 0) {  // neither --domain nor BBW_DOMAIN: a free one (domain_claim.hpp)
      domain_claim = bbw::launch::claim_free_domain(run_id);
      domain = domain_claim.domain();
    }
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: " << e.what() << "\n";
    return 1;
  }
  const std::string run_hex = bbw::dds::run_id_hex(run_id);

  // Validate the scenario before starting anything.
  std::optional<bbw::scenario::Scenario> scenario;
  bbw::faults::FaultSchedule schedule;
  try {
    auto fs = bbw::faults::load_fault_scenario(scenario_file);
    scenario = std::move(fs.scenario);
    schedule = std::move(fs.faults);
    bbw::scenario::check_four_corner_run(*scenario);
    if (!allow_large) bbw::scenario::check_run_size(*scenario);
    for (const auto& a : bbw::faults::process_actions(schedule)) {
      if (a.target == bbw::faults::Target::CCU && a.kind == bbw::faults::ProcessAction::Kind::Restart) {
        throw std::invalid_argument(scenario_file + ": restarting the CCU is not supported over DDS (a kill of the CCU ends the run)");
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: " << e.what() << "\n";
    return 2;
  }
  try {
    const auto cleared = bbw::launch::prepare_out_dir(out_dir);
    if (!cleared.removed.empty()) {
      std::cout << "bbw_launch: removed " << cleared.removed.size() << " files of an older run from " << out_dir
                << std::endl;
    }
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: " << e.what() << "\n";
    return 2;
  }
  // A SIGINT/SIGTERM before the run's processes start (while the keys are created, say) still
  // leaves a partial summary marked interrupted, and the exit is 128 + the signal.
  auto stopped_before_start = [&]() -> std::optional<int> {
    const int sig = stop_signal.load();
    if (!interrupted.load() || sig == 0) return std::nullopt;
    const std::string failure = std::string("interrupted by ") + (sig == SIGINT ? "SIGINT" : "SIGTERM") +
                                " before the run's processes started";
    std::cerr << "bbw_launch: " << failure << "\n";
    bbw::launch::PartialRun run;
    run.scenario = &*scenario;
    run.scenario_file = scenario_file;
    run.mode = mode;
    run.domain = domain;
    run.run_id = run_hex;
    run.secure = secure;
    run.out_dir = out_dir;
    run.failure = failure;
    run.interrupted = true;
    run.signal = sig;
    try {
      bbw::launch::write_partial_summary(run);
      std::cerr << "bbw_launch: partial summary in " << out_dir << "/summary.json\n";
    } catch (const std::exception& e) {
      std::cerr << "bbw_launch: partial summary failed: " << e.what() << "\n";
    }
    return 128 + sig;
  };
  if (const auto rc = stopped_before_start()) return *rc;
  if (secure) {
    // Keys: created by scripts/bbw-keys.sh when any file is missing (idempotent), then checked.
    std::error_code ec;
    if (keys_dir.empty()) keys_dir = bbw::data::root() + "/keys";
    keys_dir = std::filesystem::absolute(keys_dir, ec).lexically_normal().string();
    // One launcher at a time checks and creates the keys of a directory (two runs started at
    // once must not both write it): an flock on a lock file named after it, held until here ends.
    const std::string keys_lock = "/tmp/bbw-keys-" + std::to_string(std::hash<std::string>{}(keys_dir)) + ".lock";
    const int keys_lock_fd = ::open(keys_lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (keys_lock_fd < 0 || ::flock(keys_lock_fd, LOCK_EX) != 0) {
      std::cerr << "bbw_launch: cannot lock " << keys_lock << " for the keys in " << keys_dir << "\n";
      return 1;
    }
    struct CloseLock {
      int fd;
      ~CloseLock() { ::close(fd); }
    } close_keys_lock{keys_lock_fd};
    auto check_keys = [&]() -> std::string {
      try {
        for (const auto& id : bbw::security::identities()) bbw::security::files_for(keys_dir, id);
      } catch (const std::exception& e) {
        return e.what();
      }
      // Permissions written before runs had their own partitions (issue 17) grant no run_*
      // partition: scripts/bbw-keys.sh re-signs them (it keeps every key that still verifies).
      std::ifstream perm(keys_dir + "/fl/permissions.xml");
      const std::string text((std::istreambuf_iterator<char>(perm)), std::istreambuf_iterator<char>());
      if (text.find("run_*") == std::string::npos) return keys_dir + "/fl/permissions.xml grants no per-run partition";
      return "";
    };
    if (!check_keys().empty()) {
      std::cout << "bbw_launch: creating DDS Security keys in " << keys_dir << std::endl;
      // Test hook: BBW_LAUNCH_KEYS_SCRIPT replaces scripts/bbw-keys.sh (e.g. one that waits, so a
      // stop during key creation is exercised).
      const char* keys_script_env = std::getenv("BBW_LAUNCH_KEYS_SCRIPT");
      const std::string keys_script =
          keys_script_env && *keys_script_env ? keys_script_env : bbw::data::path("scripts/bbw-keys.sh");
      Child keys("bbw-keys.sh", {keys_script, keys_dir}, out_dir + "/keys.out", out_dir + "/keys.err");
      const auto keys_end = Clock::now() + 120s;
      std::optional<bbw::launch::ExitStatus> st;
      while (!(st = keys.wait_until(std::min(keys_end, Clock::now() + 100ms))) && Clock::now() < keys_end) {
        if (interrupted.load()) {
          keys.stop(1000ms);
          return *stopped_before_start();
        }
      }
      if (const auto rc = stopped_before_start()) return *rc;
      if (!st || !st->ok()) {
        if (!st) keys.stop(1000ms);
        std::cerr << "bbw_launch: scripts/bbw-keys.sh " << keys_dir << " failed ("
                  << (st ? st->describe() : std::string("no exit within 120 s")) << "): "
                  << last_line(out_dir + "/keys.err") << "\n";
        return 1;
      }
    }
    if (const std::string missing = check_keys(); !missing.empty()) {
      std::cerr << "bbw_launch: " << missing << "\n";
      return 2;
    }
  }
  const auto shm = bbw::dds::cleanup_stale_shm();
  if (!shm.removed.empty()) {
    std::cout << "bbw_launch: removed " << shm.removed.size() << " stale Fast DDS shared-memory files" << std::endl;
  }
  if (const auto rc = stopped_before_start()) return *rc;

  const std::string bin = bbw::launch::executable_dir();
  // Test hook: BBW_LAUNCH_CORNER_BIN replaces the corner executable (e.g. one that fails to
  // start), so the failure path is exercised with real processes.
  const char* corner_bin_env = std::getenv("BBW_LAUNCH_CORNER_BIN");
  const std::string corner_bin = corner_bin_env && *corner_bin_env ? corner_bin_env : bin + "/bbw_corner";
  const std::string dom = std::to_string(domain);
  const std::string disc = std::to_string(discovery_s);
  const auto wall0 = Clock::now();
  const auto actions = bbw::faults::process_actions(schedule);
  const bool process_faults = !actions.empty();
  // A corner restart runs every process on UDP over 127.0.0.1 without shared memory (profile
  // bbw_localhost_udp in config/dds/bbw_profiles.xml explains why).
  bool corner_restarts = false;
  for (const auto& a : actions) corner_restarts |= a.kind == bbw::faults::ProcessAction::Kind::Restart;
  const std::vector<std::string> profile_args =
      corner_restarts ? std::vector<std::string>{"--dds-participant-profile", "bbw_localhost_udp"}
                      : std::vector<std::string>{};
  // Where each corner's incarnations keep their stats and per-period log.
  auto corner_stats_file = [&](const std::string& c, unsigned n) { return bbw::launch::corner_stats_file(out_dir, c, n); };
  std::map<std::string, unsigned> incarnations;  // corner -> processes started
  auto spawn_corner = [&](const std::string& c, unsigned incarnation, double resume_at_s) {
    std::vector<std::string> argv{corner_bin, "--corner", c, "--scenario", scenario_file, "--domain", dom,
                                  "--run-id", run_hex, "--mode", mode, "--stats", corner_stats_file(c, incarnation),
                                  "--periods-log", out_dir + "/corner_" + c + "_periods.csv",
                                  "--discovery-timeout", disc};
    if (process_faults) {
      argv.push_back("--process-faults");
      // In lockstep the CCU may hold the clock for a restarted corner for up to the discovery
      // timeout: the other corners must wait for their next command at least that long.
      argv.insert(argv.end(), {"--peer-timeout", std::to_string(discovery_s + 10.0)});
    }
    if (secure) argv.insert(argv.end(), {"--secure", keys_dir});
    argv.insert(argv.end(), profile_args.begin(), profile_args.end());
    if (incarnation > 0) {
      argv.insert(argv.end(), {"--incarnation", std::to_string(incarnation), "--resume-at", std::to_string(resume_at_s)});
    }
    const std::string suffix = incarnation == 0 ? "" : "." + std::to_string(incarnation);
    children.push_back(std::make_unique<Child>("bbw_corner " + c + suffix, argv,
                                               out_dir + "/corner_" + c + suffix + ".out",
                                               out_dir + "/corner_" + c + suffix + ".err"));
    incarnations[c] = incarnation + 1;
  };
  try {
    std::vector<std::string> ccu_argv{bin + "/bbw_ccu", "--scenario", scenario_file, "--domain", dom, "--run-id", run_hex, "--mode", mode,
                                      "--out", out_dir, "--discovery-timeout", disc, "--friction-feedback", feedback};
    if (process_faults) ccu_argv.push_back("--process-faults");
    if (secure) ccu_argv.insert(ccu_argv.end(), {"--secure", keys_dir});
    ccu_argv.insert(ccu_argv.end(), profile_args.begin(), profile_args.end());
    children.push_back(std::make_unique<Child>("bbw_ccu", ccu_argv, out_dir + "/ccu.out", out_dir + "/ccu.err"));
    for (const auto& c : scenario->corners) spawn_corner(c.name, 0, 0.0);
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: " << e.what() << "\n";
    for (auto& c : children) c->stop(2000ms);
    return 1;
  }
  std::cout << "bbw_launch: " << scenario->name << ", " << mode << ", domain " << domain
            << (domain_claim.domain() >= 0 ? " (chosen free)" : "") << ", run id " << run_hex << ", "
            << children.size() << " processes, discovery deadline " << discovery_s << " s"
            << (process_faults ? ", process faults scheduled" : "") << std::endl;

  // Bound on the whole run: discovery plus a generous multiple of the simulated duration (and
  // one more discovery per scheduled restart).
  std::size_t restarts_planned = 0;
  for (const auto& a : actions) restarts_planned += a.kind == bbw::faults::ProcessAction::Kind::Restart ? 1 : 0;
  const double bound_s = discovery_s * static_cast<double>(1 + restarts_planned) +
                         (mode == "lockstep" ? 10.0 * scenario->duration_s + 60.0 : 1.5 * scenario->duration_s + 20.0);
  const auto deadline = wall0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(bound_s));
  // Scheduled kills not yet carried out, per process name; restarts waiting for their time.
  std::map<std::string, std::vector<const bbw::faults::ProcessAction*>> kills_due;
  for (const auto& a : actions) {
    if (a.kind == bbw::faults::ProcessAction::Kind::Kill) {
      kills_due[a.target == bbw::faults::Target::CCU ? std::string("bbw_ccu") : std::string(bbw::faults::to_string(a.target))]
          .push_back(&a);
    }
  }
  struct PendingRestart {
    std::string corner;
    double resume_at_s;
    Clock::time_point when;
  };
  std::vector<PendingRestart> restarts;
  std::set<const Child*> killed_by_schedule, handled;
  bool ccu_killed = false;
  double ccu_killed_at_s = -1.0;
  std::string failure;
  auto corner_of = [](const std::string& name) { return name.substr(11, 2); };  // "bbw_corner XX[.n]"
  for (;;) {
    // Scheduled kills need a quick look at stopped children; otherwise wake every 200 ms to
    // notice SIGINT/SIGTERM (the children get it from the terminal's process group too).
    const auto wake = std::min(deadline, Clock::now() + (process_faults ? 2ms : 200ms));
    std::vector<Child*> raw;
    for (auto& c : children) raw.push_back(c.get());
    bbw::launch::wait_any(raw, wake);
    if (interrupted.load()) {
      failure = std::string("interrupted by ") + (stop_signal.load() == SIGINT ? "SIGINT" : "SIGTERM");
      break;
    }
    // A process that froze itself at its scheduled kill: kill it now.
    for (auto& c : children) {
      if (!c->take_stop()) continue;
      const bool is_ccu = c->name() == "bbw_ccu";
      auto& due = kills_due[is_ccu ? std::string("bbw_ccu") : corner_of(c->name())];
      if (due.empty()) {
        c->send_signal(SIGCONT);  // stopped by someone else: not ours to kill
        continue;
      }
      const auto* kill = due.front();
      due.erase(due.begin());
      c->send_signal(SIGKILL);
      c->wait_until(Clock::now() + 2000ms);
      killed_by_schedule.insert(c.get());
      std::cout << "bbw_launch: killed " << c->name() << " as scheduled at " << kill->at_s << " s" << std::endl;
      if (is_ccu) {
        ccu_killed = true;
        ccu_killed_at_s = kill->at_s;
        continue;
      }
      for (const auto& a : actions) {
        if (a.kind == bbw::faults::ProcessAction::Kind::Restart && a.target == kill->target && a.at_s > kill->at_s) {
          const double after_s = mode == "lockstep" ? 0.0 : a.at_s - kill->at_s;
          restarts.push_back({corner_of(c->name()), a.at_s,
                              Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(after_s))});
          break;
        }
      }
    }
    for (auto it = restarts.begin(); it != restarts.end();) {
      if (Clock::now() < it->when) {
        ++it;
        continue;
      }
      try {
        spawn_corner(it->corner, incarnations[it->corner], it->resume_at_s);
        std::cout << "bbw_launch: restarted corner " << it->corner << " to rejoin at " << it->resume_at_s << " s" << std::endl;
      } catch (const std::exception& e) {
        failure = "restart of corner " + it->corner + " failed: " + e.what();
      }
      it = restarts.erase(it);
    }
    if (!failure.empty()) break;
    for (auto& c : children) {
      if (!c->poll() || handled.count(c.get()) > 0) continue;
      handled.insert(c.get());
      if (killed_by_schedule.count(c.get()) > 0) continue;
      const auto status = *c->status();
      if (!status.ok()) {
        const std::string name = c->name();
        std::string err_file = out_dir + (name == "bbw_ccu" ? "/ccu.err" : "/corner_" + name.substr(11) + ".err");
        failure = name + " failed: " + reason(status);
        const std::string msg = last_line(err_file);
        if (!msg.empty()) failure += ": " + msg;
        break;
      }
    }
    if (!failure.empty()) break;
    bool running = false;
    for (auto& c : children) running = running || !c->poll();
    if (!running && restarts.empty()) break;
    if (Clock::now() >= deadline) {
      failure = "run exceeded its wall-time bound of " + std::to_string(static_cast<int>(bound_s)) + " s";
      break;
    }
  }
  if (!failure.empty()) {
    // Which processes ended on their own (the lost ones, unless scheduled) before the others
    // are stopped; then a partial summary from whatever each process logged.
    std::vector<bbw::launch::ProcessEnd> ends;
    for (auto& c : children) {
      bbw::launch::ProcessEnd e;
      e.name = c->name();
      e.ended_by_itself = c->poll().has_value();
      e.scheduled_kill = killed_by_schedule.count(c.get()) > 0;
      ends.push_back(e);
    }
    for (auto& c : children) c->stop(3000ms);
    for (std::size_t i = 0; i < children.size(); ++i) {
      ends[i].status = children[i]->status() ? children[i]->status()->describe() : std::string("unknown");
      ends[i].ok = children[i]->status() && children[i]->status()->ok();
      ends[i].exit_code = children[i]->status() && children[i]->status()->exited ? children[i]->status()->code : -1;
    }
    const int sig = stop_signal.load();
    std::cerr << "bbw_launch: " << failure << " (logs in " << out_dir << ")\n";
    bbw::launch::PartialRun run;
    run.scenario = &*scenario;
    run.scenario_file = scenario_file;
    run.mode = mode;
    run.domain = domain;
    run.run_id = run_hex;
    run.secure = secure;
    run.out_dir = out_dir;
    run.failure = failure;
    run.interrupted = sig != 0;
    run.signal = sig;
    run.processes = ends;
    run.incarnations = incarnations;
    try {
      const auto lost = bbw::launch::write_partial_summary(run);
      for (const auto& name : lost) std::cerr << "bbw_launch: lost process: " << name << "\n";
      std::cerr << "bbw_launch: partial summary in " << out_dir << "/summary.json\n";
    } catch (const std::exception& e) {
      std::cerr << "bbw_launch: partial summary failed: " << e.what() << "\n";
    }
    return sig != 0 ? 128 + sig : 1;
  }
  for (const auto& [name, due] : kills_due) {
    if (!due.empty()) {
      std::cerr << "bbw_launch: the scheduled kill of " << name << " at " << due.front()->at_s
                << " s was never reached (the process finished first)\n";
      return 1;
    }
  }
  if (ccu_killed) {
    std::cout << "bbw_launch: the run was ended by the injected CCU kill at " << ccu_killed_at_s
              << " s; the corners ran on in their safe state" << std::endl;
  }
  const double launch_wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();

  // Summary.
  try {
    bbw::launch::CompletedRun run;
    run.scenario = &*scenario;
    run.schedule = &schedule;
    run.scenario_file = scenario_file;
    run.mode = mode;
    run.run_id = run_hex;
    run.out_dir = out_dir;
    run.friction_feedback = feedback;
    run.domain = domain;
    run.secure = secure;
    run.report = report;
    run.incarnations = incarnations;
    run.ended_by_injected_ccu_kill = ccu_killed;
    run.launch_wall_s = launch_wall_s;
    const auto t = bbw::launch::write_run_summary(run);
    std::cout << "bbw_launch: done: simulated " << t.simulated_s << " s in " << t.wall_s << " s (real-time factor "
              << (t.wall_s > 0 ? t.simulated_s / t.wall_s : 0.0) << "), samples published " << t.published
              << ", received " << t.received << ", gaps " << t.gaps << "; " << out_dir << "/summary.json" << std::endl;
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: summary failed: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
