// bbw_launch (./bbw run): the CCU and one process per corner over Fast DDS on this host.
//
//   bbw_launch SCENARIO.yaml --out DIR [--mode lockstep|realtime] [--domain N]
//              [--discovery-timeout S] [--friction-feedback on|off] [--no-report]
//              [--secure [--keys DIR]] [--standby]
//
// --standby (or the scenario's `standby: true`): a hot-standby CCU too (issue 16, docs/faults.md
// "Hot-standby CCU"): bbw_ccu (primary) and bbw_ccu_standby both run warm, their commands under
// DDS exclusive ownership; summary.json gets a `failover` object.
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
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include "bbw/common/data_path.hpp"
#include "bbw/dds/run_id.hpp"
#include "bbw/dds/shm_cleanup.hpp"
#include "bbw/runtime/failover_stats.hpp"
#include "bbw/runtime/signals.hpp"
#include "domain_claim.hpp"
#include "options.hpp"
#include "out_dir.hpp"
#include "partial_summary.hpp"
#include "summary.hpp"
#include "vehicle_summary.hpp"
#include "supervisor.hpp"

namespace {

std::string signal_name(int sig) { return sig == SIGINT ? "SIGINT" : "SIGTERM"; }

// The partial summary of a run that did not finish (bbw/launch partial_summary.hpp); returns
// the launcher's exit code: 128 + the signal when stopped, else 1.
int write_partial(const bbw::launch::RunPlan& plan, const std::string& failure, int sig,
                  const std::vector<bbw::launch::ProcessEnd>& processes,
                  const std::map<std::string, unsigned>& incarnations) {
  std::cerr << "bbw_launch: " << failure << " (logs in " << plan.out_dir << ")\n";
  bbw::launch::PartialRun run;
  run.scenario = plan.scenario;
  run.scenario_file = plan.scenario_file;
  run.mode = plan.mode;
  run.domain = plan.domain;
  run.run_id = plan.run_id;
  run.secure = plan.secure;
  run.out_dir = plan.out_dir;
  run.failure = failure;
  run.interrupted = sig != 0;
  run.signal = sig;
  run.processes = processes;
  run.incarnations = incarnations;
  try {
    const auto lost = bbw::launch::write_partial_summary(run);
    for (const auto& name : lost) std::cerr << "bbw_launch: lost process: " << name << "\n";
    std::cerr << "bbw_launch: partial summary in " << plan.out_dir << "/summary.json\n";
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: partial summary failed: " << e.what() << "\n";
  }
  return sig != 0 ? 128 + sig : 1;
}

}  // namespace

int main(int argc, char** argv) {
  // First, before any thread exists: SIGINT/SIGTERM go to the watcher only.
  std::atomic<int> stop_signal{0};
  bbw::runtime::SignalWatcher signals([&](int sig) { stop_signal.store(sig); });

  bbw::launch::Options opt;
  int domain = -1;
  try {
    opt = bbw::launch::parse_options(argc, argv);
    if (opt.help) {
      std::cout << bbw::launch::kUsage;
      return 0;
    }
    domain = bbw::launch::requested_domain(opt);
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: " << e.what() << "\n" << bbw::launch::kUsage;
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
  // Validate the scenario and prepare the output folder before starting anything.
  std::optional<bbw::launch::LoadedRun> loaded;
  try {
    loaded = bbw::launch::load_run(opt);
    const auto cleared = bbw::launch::prepare_out_dir(opt.out_dir);
    if (!cleared.removed.empty()) {
      std::cout << "bbw_launch: removed " << cleared.removed.size() << " files of an older run from " << opt.out_dir
                << std::endl;
    }
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: " << e.what() << "\n";
    return 2;
  }
  if (opt.secure) {
    std::error_code ec;
    if (opt.keys_dir.empty()) opt.keys_dir = bbw::data::root() + "/keys";
    opt.keys_dir = std::filesystem::absolute(opt.keys_dir, ec).lexically_normal().string();
  }
  bbw::launch::RunPlan plan;
  plan.scenario = &loaded->scenario;
  plan.schedule = &loaded->schedule;
  plan.scenario_file = opt.scenario_file;
  plan.out_dir = opt.out_dir;
  plan.mode = opt.mode;
  plan.friction_feedback = opt.friction_feedback;
  plan.run_id = bbw::dds::run_id_hex(run_id);
  plan.keys_dir = opt.keys_dir;
  plan.domain = domain;
  plan.discovery_s = opt.discovery_s;
  plan.secure = opt.secure;
  plan.processes = loaded->processes;
  plan.standby = loaded->schedule.standby;  // the scenario's standby: true, or --standby

  // A SIGINT/SIGTERM before the run's processes start (while the keys are created, say) still
  // leaves a partial summary marked interrupted, and the exit is 128 + the signal.
  auto stopped_before_start = [&]() -> std::optional<int> {
    const int sig = stop_signal.load();
    if (sig == 0) return std::nullopt;
    return write_partial(plan, "interrupted by " + signal_name(sig) + " before the run's processes started", sig, {}, {});
  };
  if (const auto rc = stopped_before_start()) return *rc;
  if (opt.secure) {
    std::string error;
    bool bad_keys = false;
    const auto keys = bbw::launch::ensure_keys(opt.keys_dir, opt.out_dir, stop_signal, error, bad_keys);
    if (keys == bbw::launch::KeysResult::Interrupted) return *stopped_before_start();
    if (keys == bbw::launch::KeysResult::Failed) {
      std::cerr << "bbw_launch: " << error << "\n";
      return bad_keys ? 2 : 1;
    }
  }
  const auto shm = bbw::dds::cleanup_stale_shm();
  if (!shm.removed.empty()) {
    std::cout << "bbw_launch: removed " << shm.removed.size() << " stale Fast DDS shared-memory files" << std::endl;
  }
  if (const auto rc = stopped_before_start()) return *rc;

  const auto wall0 = std::chrono::steady_clock::now();
  bbw::launch::Supervisor supervisor(plan, stop_signal);
  try {
    supervisor.start();
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: " << e.what() << "\n";
    return 1;
  }
  std::cout << "bbw_launch: " << plan.scenario->name << ", " << plan.mode << ", domain " << domain
            << (domain_claim.domain() >= 0 ? " (chosen free)" : "") << ", run id " << plan.run_id << ", "
            << supervisor.processes() << " processes, discovery deadline " << plan.discovery_s << " s"
            << (supervisor.process_faults() ? ", process faults scheduled" : "") << std::endl;
  const bbw::launch::SupervisedRun result = supervisor.run();
  if (!result.failure.empty()) {
    // A partial summary from whatever each process logged.
    return write_partial(plan, result.failure, stop_signal.load(), result.processes, result.incarnations);
  }
  if (!result.unreached_kill.empty()) {
    std::cerr << "bbw_launch: " << result.unreached_kill << "\n";
    return 1;
  }
  if (result.ccu_killed) {
    std::cout << "bbw_launch: the run was ended by the injected CCU kill at " << result.ccu_killed_at_s
              << " s; the corners ran on in their safe state" << std::endl;
  }
  try {
    bbw::launch::CompletedRun run;
    run.scenario = plan.scenario;
    run.schedule = plan.schedule;
    run.scenario_file = plan.scenario_file;
    run.mode = plan.mode;
    run.run_id = plan.run_id;
    run.out_dir = plan.out_dir;
    run.friction_feedback = plan.friction_feedback;
    run.domain = domain;
    run.secure = plan.secure;
    run.report = opt.report;
    run.incarnations = result.incarnations;
    run.processes = plan.processes;
    run.ended_by_injected_ccu_kill = result.ccu_killed;
    run.standby = plan.standby;
    if (plan.standby) {
      // Summarise the CCU that ran on: the standby after the primary's failure.
      const auto primary = bbw::runtime::load_ccu_failover(plan.out_dir + "/ccu_failover.stats");
      const auto standby = bbw::runtime::load_ccu_failover(plan.out_dir + "/standby/ccu_failover.stats");
      if (!primary.failure.empty() && (standby.failure.empty() || standby.failed_sim_s > primary.failed_sim_s)) {
        run.ccu_dir = plan.out_dir + "/standby";
      }
    }
    run.launch_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    const auto t = bbw::launch::write_run_summary(run);
    if (plan.runs("vehicle")) bbw::launch::merge_vehicle_summary(plan.out_dir);
    std::cout << "bbw_launch: done: simulated " << t.simulated_s << " s in " << t.wall_s << " s (real-time factor "
              << (t.wall_s > 0 ? t.simulated_s / t.wall_s : 0.0) << "), samples published " << t.published
              << ", received " << t.received << ", gaps " << t.gaps << "; " << plan.out_dir << "/summary.json"
              << std::endl;
  } catch (const std::exception& e) {
    std::cerr << "bbw_launch: summary failed: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
