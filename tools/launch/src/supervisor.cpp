#include "supervisor.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <thread>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>

#include "bbw/common/data_path.hpp"
#include "bbw/security/dds_security.hpp"
#include "summary.hpp"

namespace bbw::launch {

namespace {

using namespace std::chrono_literals;

std::string last_line(const std::string& file) {
  std::ifstream f(file);
  std::string line, last;
  while (std::getline(f, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

std::string reason(const ExitStatus& s) {
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

std::string signal_name(int sig) { return sig == SIGINT ? "SIGINT" : "SIGTERM"; }

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

KeysResult ensure_keys(const std::string& keys_dir, const std::string& out_dir, const std::atomic<int>& stop_signal,
                       std::string& error, bool& bad_keys) {
  bad_keys = false;
  // One launcher at a time checks and creates the keys of a directory (two runs started at
  // once must not both write it): an flock on a lock file named after it, held until here ends.
  const std::string keys_lock = "/tmp/bbw-keys-" + std::to_string(std::hash<std::string>{}(keys_dir)) + ".lock";
  // The wait for another launcher's lock is a poll, so a stop signal still ends it.
  const int keys_lock_fd = ::open(keys_lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  if (keys_lock_fd < 0) {
    error = "cannot open " + keys_lock + " for the keys in " + keys_dir;
    return KeysResult::Failed;
  }
  struct CloseLock {
    int fd;
    ~CloseLock() { ::close(fd); }
  } close_keys_lock{keys_lock_fd};
  while (::flock(keys_lock_fd, LOCK_EX | LOCK_NB) != 0) {
    if (errno != EWOULDBLOCK && errno != EINTR) {
      error = "cannot lock " + keys_lock + " for the keys in " + keys_dir;
      return KeysResult::Failed;
    }
    if (stop_signal.load() != 0) return KeysResult::Interrupted;
    std::this_thread::sleep_for(50ms);
  }
  auto check_keys = [&]() -> std::string {
    try {
      for (const auto& id : security::identities()) security::files_for(keys_dir, id);
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
        keys_script_env && *keys_script_env ? keys_script_env : data::path("scripts/bbw-keys.sh");
    Child keys("bbw-keys.sh", {keys_script, keys_dir}, out_dir + "/keys.out", out_dir + "/keys.err");
    const auto keys_end = Clock::now() + 120s;
    std::optional<ExitStatus> st;
    while (!(st = keys.wait_until(std::min(keys_end, Clock::now() + 100ms))) && Clock::now() < keys_end) {
      if (stop_signal.load() != 0) break;
    }
    if (stop_signal.load() != 0) {
      if (!st) keys.stop(1000ms);
      return KeysResult::Interrupted;
    }
    if (!st || !st->ok()) {
      if (!st) keys.stop(1000ms);
      error = "scripts/bbw-keys.sh " + keys_dir + " failed (" + (st ? st->describe() : std::string("no exit within 120 s")) +
              "): " + last_line(out_dir + "/keys.err");
      return KeysResult::Failed;
    }
  }
  if (const std::string missing = check_keys(); !missing.empty()) {
    error = missing;
    bad_keys = true;
    return KeysResult::Failed;
  }
  return KeysResult::Ready;
}

Supervisor::Supervisor(RunPlan plan, const std::atomic<int>& stop_signal)
    : plan_(std::move(plan)), stop_signal_(stop_signal), actions_(faults::process_actions(*plan_.schedule)) {
  // A corner restart runs every process on UDP over 127.0.0.1 without shared memory (profile
  // bbw_localhost_udp in config/dds/bbw_profiles.xml explains why).
  bool corner_restarts = false;
  for (const auto& a : actions_) corner_restarts |= a.kind == faults::ProcessAction::Kind::Restart;
  // So does a run with a hot-standby CCU: a CCU stopped (hung) inside a shared-memory port
  // operation holds that port's lock, and its peers' sends through it wait until it is continued
  // (seen: two corners got no command for the whole 0.5 s hang; docs/faults.md).
  if (corner_restarts || plan_.standby) profile_args_ = {"--dds-participant-profile", "bbw_localhost_udp"};
  bin_ = runtime::executable_dir();
  // Test hook: BBW_LAUNCH_CORNER_BIN replaces the corner executable (e.g. one that fails to
  // start), so the failure path is exercised with real processes.
  const char* corner_bin_env = std::getenv("BBW_LAUNCH_CORNER_BIN");
  corner_bin_ = corner_bin_env && *corner_bin_env ? corner_bin_env : bin_ + "/bbw_corner";
}

bool RunPlan::runs(const std::string& process) const {
  return std::find(processes.begin(), processes.end(), process) != processes.end();
}

Supervisor::~Supervisor() {
  for (auto& c : children_) {
    if (!c->status()) c->stop(2000ms);
  }
}

void Supervisor::spawn_corner(const std::string& c, unsigned incarnation, double resume_at_s) {
  const std::string suffix = incarnation_suffix(incarnation);
  std::vector<std::string> args{corner_bin_, "--corner", c, "--scenario", plan_.scenario_file, "--domain",
                                std::to_string(plan_.domain), "--run-id", plan_.run_id, "--mode", plan_.mode,
                                "--stats", plan_.out_dir + "/corner_" + c + suffix + ".stats",
                                "--periods-log", plan_.out_dir + "/corner_" + c + "_periods.csv",
                                "--discovery-timeout", std::to_string(plan_.discovery_s)};
  if (process_faults()) {
    args.push_back("--process-faults");
    // In lockstep the CCU may hold the clock for a restarted corner for up to the discovery
    // timeout: the other corners must wait for their next command at least that long.
    args.insert(args.end(), {"--peer-timeout", std::to_string(plan_.discovery_s + 10.0)});
  }
  if (plan_.secure) args.insert(args.end(), {"--secure", plan_.keys_dir});
  if (plan_.standby) args.push_back("--standby");
  args.insert(args.end(), profile_args_.begin(), profile_args_.end());
  if (incarnation > 0) {
    args.insert(args.end(), {"--incarnation", std::to_string(incarnation), "--resume-at", std::to_string(resume_at_s)});
  }
  children_.push_back(std::make_unique<Child>("bbw_corner " + c + suffix, args,
                                              plan_.out_dir + "/corner_" + c + suffix + ".out",
                                              plan_.out_dir + "/corner_" + c + suffix + ".err"));
  incarnations_[c] = incarnation + 1;
}

void Supervisor::start() {
  wall0_ = Clock::now();
  try {
    std::vector<std::string> ccu_args{bin_ + "/bbw_ccu", "--scenario", plan_.scenario_file, "--domain",
                                      std::to_string(plan_.domain), "--run-id", plan_.run_id, "--mode", plan_.mode,
                                      "--out", plan_.out_dir, "--discovery-timeout", std::to_string(plan_.discovery_s),
                                      "--friction-feedback", plan_.friction_feedback};
    if (process_faults()) ccu_args.push_back("--process-faults");
    if (plan_.secure) ccu_args.insert(ccu_args.end(), {"--secure", plan_.keys_dir});
    ccu_args.insert(ccu_args.end(), profile_args_.begin(), profile_args_.end());
    if (plan_.standby) {
      // The hot-standby CCU: the same command line, its own role, logs and stats (issue 16).
      std::vector<std::string> standby_args = ccu_args;
      standby_args.insert(standby_args.end(), {"--standby", "--role", "standby"});
      const std::string dir = plan_.out_dir + "/standby";
      for (std::size_t i = 0; i + 1 < standby_args.size(); ++i) {
        if (standby_args[i] == "--out") standby_args[i + 1] = dir;
      }
      std::filesystem::create_directories(dir);
      ccu_args.insert(ccu_args.end(), {"--standby", "--role", "primary"});
      children_.push_back(std::make_unique<Child>("bbw_ccu_standby", standby_args, plan_.out_dir + "/ccu_standby.out",
                                                  plan_.out_dir + "/ccu_standby.err"));
    }
    children_.push_back(std::make_unique<Child>("bbw_ccu", ccu_args, plan_.out_dir + "/ccu.out", plan_.out_dir + "/ccu.err"));
    for (const auto& c : plan_.scenario->corners) {
      if (plan_.runs(c.name)) spawn_corner(c.name, 0, 0.0);
    }
    // The further processes the scenario declares (a vehicle run: bbw_vehicle, bbw_pedal).
    for (const std::string& p : {std::string("vehicle"), std::string("pedal")}) {
      if (!plan_.runs(p)) continue;
      const std::string name = "bbw_" + p;
      std::vector<std::string> args{bin_ + "/" + name, "--scenario", plan_.scenario_file, "--domain",
                                    std::to_string(plan_.domain), "--run-id", plan_.run_id, "--mode", plan_.mode,
                                    "--discovery-timeout", std::to_string(plan_.discovery_s)};
      if (p == "vehicle") args.insert(args.end(), {"--out", plan_.out_dir});
      args.insert(args.end(), profile_args_.begin(), profile_args_.end());
      children_.push_back(std::make_unique<Child>(name, args, plan_.out_dir + "/" + p + ".out", plan_.out_dir + "/" + p + ".err"));
    }
  } catch (...) {
    for (auto& c : children_) c->stop(2000ms);
    throw;
  }
}

SupervisedRun Supervisor::run() {
  SupervisedRun out;
  const scenario::Scenario& scenario = *plan_.scenario;
  // Bound on the whole run: discovery plus a generous multiple of the simulated duration (and
  // one more discovery per scheduled restart).
  std::size_t restarts_planned = 0;
  for (const auto& a : actions_) restarts_planned += a.kind == faults::ProcessAction::Kind::Restart ? 1 : 0;
  const double bound_s = plan_.discovery_s * static_cast<double>(1 + restarts_planned) +
                         (plan_.mode == "lockstep" ? 10.0 * scenario.duration_s + 60.0 : 1.5 * scenario.duration_s + 20.0);
  const auto deadline = wall0_ + seconds(bound_s);
  // Scheduled kills not yet carried out, per process name; restarts waiting for their time.
  // A process that stops itself at a scheduled kill is SIGKILLed; at a scheduled hang (a CCU of
  // a standby run) it is left stopped, and continued at its resume (if any).
  auto key_of = [](faults::Target t) {
    return t == faults::Target::CCU          ? std::string("bbw_ccu")
           : t == faults::Target::CcuStandby ? std::string("bbw_ccu_standby")
                                             : std::string(faults::to_string(t));
  };
  std::map<std::string, std::vector<const faults::ProcessAction*>> kills_due;
  for (const auto& a : actions_) {
    if (a.kind == faults::ProcessAction::Kind::Kill || a.kind == faults::ProcessAction::Kind::Hang) {
      kills_due[key_of(a.target)].push_back(&a);
    }
  }
  struct PendingResume {
    Child* child;
    Clock::time_point when;
  };
  std::vector<PendingResume> resumes;
  std::set<Child*> hung;  // stopped by a scheduled hang, not (yet) continued
  int ccus_down = 0;      // killed or hung for good
  struct PendingRestart {
    std::string corner;
    double resume_at_s;
    Clock::time_point when;
  };
  std::vector<PendingRestart> restarts;
  std::set<const Child*> killed_by_schedule, handled;
  std::string& failure = out.failure;
  auto corner_of = [](const std::string& name) { return name.substr(11, 2); };  // "bbw_corner XX[.n]"
  for (;;) {
    // Scheduled kills need a quick look at stopped children; otherwise wake every 200 ms to
    // notice SIGINT/SIGTERM (the children get it from the terminal's process group too).
    const auto wake = std::min(deadline, Clock::now() + (process_faults() ? 2ms : 200ms));
    std::vector<Child*> raw;
    for (auto& c : children_) raw.push_back(c.get());
    runtime::wait_any(raw, wake);
    if (const int sig = stop_signal_.load(); sig != 0) {
      failure = "interrupted by " + signal_name(sig);
      break;
    }
    // A process that froze itself at its scheduled kill: kill it now.
    for (auto& c : children_) {
      if (!c->take_stop()) continue;
      const bool is_ccu = c->name() == "bbw_ccu" || c->name() == "bbw_ccu_standby";
      auto& due = kills_due[is_ccu ? c->name() : corner_of(c->name())];
      if (due.empty()) {
        c->send_signal(SIGCONT);  // stopped by someone else: not ours to kill
        continue;
      }
      const auto* kill = due.front();
      due.erase(due.begin());
      if (kill->kind == faults::ProcessAction::Kind::Hang) {
        hung.insert(c.get());
        bool resumed = false;
        for (const auto& a : actions_) {
          if (a.kind == faults::ProcessAction::Kind::Resume && a.target == kill->target && a.at_s > kill->at_s) {
            resumes.push_back({c.get(), Clock::now() + seconds(a.at_s - kill->at_s)});
            resumed = true;
            break;
          }
        }
        if (!resumed) ++ccus_down;
        std::cout << "bbw_launch: " << c->name() << " hangs as scheduled at " << kill->at_s << " s" << std::endl;
        continue;
      }
      c->send_signal(SIGKILL);
      c->wait_until(Clock::now() + 2000ms);
      killed_by_schedule.insert(c.get());
      std::cout << "bbw_launch: killed " << c->name() << " as scheduled at " << kill->at_s << " s" << std::endl;
      if (is_ccu) {
        // Without a standby a CCU kill ends the CCU's part in the run; with one, only when both are down.
        if (!plan_.standby || ++ccus_down == 2) {
          out.ccu_killed = true;
          out.ccu_killed_at_s = kill->at_s;
        }
        continue;
      }
      for (const auto& a : actions_) {
        if (a.kind == faults::ProcessAction::Kind::Restart && a.target == kill->target && a.at_s > kill->at_s) {
          const double after_s = plan_.mode == "lockstep" ? 0.0 : a.at_s - kill->at_s;
          restarts.push_back({corner_of(c->name()), a.at_s, Clock::now() + seconds(after_s)});
          break;
        }
      }
    }
    for (auto it = resumes.begin(); it != resumes.end();) {
      if (Clock::now() < it->when) {
        ++it;
        continue;
      }
      it->child->send_signal(SIGCONT);
      hung.erase(it->child);
      std::cout << "bbw_launch: continued " << it->child->name() << " as scheduled" << std::endl;
      it = resumes.erase(it);
    }
    for (auto it = restarts.begin(); it != restarts.end();) {
      if (Clock::now() < it->when) {
        ++it;
        continue;
      }
      try {
        spawn_corner(it->corner, incarnations_[it->corner], it->resume_at_s);
        std::cout << "bbw_launch: restarted corner " << it->corner << " to rejoin at " << it->resume_at_s << " s" << std::endl;
      } catch (const std::exception& e) {
        failure = "restart of corner " + it->corner + " failed: " + e.what();
      }
      it = restarts.erase(it);
    }
    if (!failure.empty()) break;
    for (auto& c : children_) {
      if (!c->poll() || handled.count(c.get()) > 0) continue;
      handled.insert(c.get());
      if (killed_by_schedule.count(c.get()) > 0) continue;
      const auto status = *c->status();
      if (!status.ok()) {
        const std::string name = c->name();
        const std::string err_file = plan_.out_dir + (name == "bbw_ccu"           ? std::string("/ccu.err")
                                                      : name == "bbw_ccu_standby" ? std::string("/ccu_standby.err")
                                                                                  : "/corner_" + name.substr(11) + ".err");
        failure = name + " failed: " + reason(status);
        const std::string msg = last_line(err_file);
        if (!msg.empty()) failure += ": " + msg;
        break;
      }
    }
    if (!failure.empty()) break;
    bool running = false;
    for (auto& c : children_) running = running || (!c->poll() && hung.count(c.get()) == 0);
    if (!running && restarts.empty() && resumes.empty()) {
      // Only processes hung for good are left: the run is over; they end as scheduled.
      for (Child* h : hung) {
        h->send_signal(SIGKILL);
        h->wait_until(Clock::now() + 2000ms);
        killed_by_schedule.insert(h);
        handled.insert(h);
      }
      if (plan_.standby && ccus_down == 2) out.ccu_killed = true;
      break;
    }
    if (Clock::now() >= deadline) {
      failure = "run exceeded its wall-time bound of " + std::to_string(static_cast<int>(bound_s)) + " s";
      break;
    }
  }
  out.incarnations = incarnations_;
  if (!failure.empty()) {
    // Which processes ended on their own (the lost ones, unless scheduled) before the others
    // are stopped.
    for (auto& c : children_) {
      ProcessEnd e;
      e.name = c->name();
      e.ended_by_itself = c->poll().has_value();
      e.scheduled_kill = killed_by_schedule.count(c.get()) > 0;
      out.processes.push_back(e);
    }
    for (auto& c : children_) c->stop(3000ms);
    for (std::size_t i = 0; i < children_.size(); ++i) {
      const auto& st = children_[i]->status();
      out.processes[i].status = st ? st->describe() : std::string("unknown");
      out.processes[i].ok = st && st->ok();
      out.processes[i].exit_code = st && st->exited ? st->code : -1;
    }
    return out;
  }
  for (const auto& [name, due] : kills_due) {
    if (!due.empty()) {
      std::ostringstream m;
      m << "the scheduled kill of " << name << " at " << due.front()->at_s
        << " s was never reached (the process finished first)";
      out.unreached_kill = m.str();
      break;
    }
  }
  return out;
}

}  // namespace bbw::launch
