#include "options.hpp"

#include <algorithm>

#include <cstdlib>
#include <stdexcept>

#include "bbw/dds/domain.hpp"
#include "bbw/runtime/process_cli.hpp"
#include "bbw/faults/link_faults.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/vehicle_run/vehicle_scenario.hpp"
#include "bbw/scenario/run_checks.hpp"

namespace bbw::launch {

const char* const kUsage =
    "usage: bbw_launch SCENARIO.yaml --out DIR [--mode lockstep|realtime] [--domain N]\n"
    "                  [--discovery-timeout S] [--friction-feedback on|off] [--no-report]\n"
    "                  [--secure [--keys DIR]] [--allow-large] [--standby]\n";

Options parse_options(int argc, char** argv) {
  Options o;
  for (runtime::ArgCursor args(argc, argv); !args.done();) {
    const std::string k = args.flag();
    auto next = [&] { return args.value(); };
    if (k == "--out") o.out_dir = next();
    else if (k == "--mode") runtime::parse_clock_mode(o.mode = next());
    else if (k == "--domain") o.domain_arg = next();
    else if (k == "--discovery-timeout") {
      o.discovery_s = static_cast<double>(runtime::seconds_arg(k, next(), 600.0).count()) / 1000.0;
    } else if (k == "--friction-feedback") o.friction_feedback = next();
    else if (k == "--no-report") o.report = false;
    else if (k == "--secure") o.secure = true;
    else if (k == "--keys") o.keys_dir = next();
    else if (k == "--allow-large") o.allow_large = true;
    else if (k == "--standby") o.standby = true;
    else if (k == "-h" || k == "--help") {
      o.help = true;
      return o;
    } else if (!k.empty() && k[0] == '-') throw std::invalid_argument("unknown argument '" + k + "'");
    else if (o.scenario_file.empty()) o.scenario_file = k;
    else throw std::invalid_argument("unexpected argument '" + k + "'");
  }
  if (o.scenario_file.empty()) throw std::invalid_argument("a scenario file is required");
  if (o.out_dir.empty()) throw std::invalid_argument("--out DIR is required");
  if (o.friction_feedback != "on" && o.friction_feedback != "off") {
    throw std::invalid_argument("--friction-feedback must be on or off");
  }
  return o;
}

int requested_domain(const Options& o) { return dds::resolve_domain_id(o.domain_arg, std::getenv("BBW_DOMAIN"), -1); }

LoadedRun load_run(const Options& o) {
  LoadedRun r;
  if (vehicle_run::is_vehicle_scenario(o.scenario_file)) {
    // A vehicle scenario declares its processes: the CCU, the corners, the vehicle, the pedal.
    auto vs = vehicle_run::load_vehicle_scenario(o.scenario_file);
    if (o.mode != "lockstep") throw std::invalid_argument(o.scenario_file + ": a vehicle scenario runs in lockstep only");
    if (o.secure) throw std::invalid_argument(o.scenario_file + ": --secure is not supported for vehicle scenarios yet");
    r.scenario = std::move(vs.corners.scenario);
    r.scenario.name = vs.name;  // the run is the vehicle scenario's (its calipers' file is a part)
    r.schedule = std::move(vs.corners.faults);
    // A corner's process killed for good: the CCU and the vehicle learn it from its writers' lost
    // liveliness while they wait for its period in lockstep, so the run is the in-process one
    // (SystemVehicleRun.ALostCornerOverDdsEqualsTheInProcessRun). A restart, a hang or a CCU fault
    // has no lockstep rejoin with the vehicle and pedal (the vehicle scenario's loader takes kills
    // only; checked here too, as the launcher's own rule).
    for (const faults::ProcessAction& a : faults::process_actions(r.schedule)) {
      if (a.kind != faults::ProcessAction::Kind::Kill || faults::is_ccu(a.target)) {
        throw std::invalid_argument(o.scenario_file +
                                    ": over Fast DDS a vehicle scenario takes only a corner process killed for good "
                                    "(no restart, hang or CCU fault); run this one in process (bbw_vehicle_inproc)");
      }
    }
    r.processes = vs.processes;
  } else {
    auto fs = faults::load_fault_scenario(o.scenario_file);
    r.scenario = std::move(fs.scenario);
    r.schedule = std::move(fs.faults);
    std::vector<std::string> corners;
    for (const auto& c : r.scenario.corners) corners.push_back(c.name);
    r.processes = faults::run_processes(r.scenario.processes, corners, r.schedule);
  }
  scenario::check_four_corner_run(r.scenario);
  if (o.standby) r.schedule.standby = true;
  if (r.schedule.standby && std::find(r.processes.begin(), r.processes.end(), "ccu_standby") == r.processes.end()) {
    r.processes.push_back("ccu_standby");  // --standby on a scenario that declares its processes
  }
  for (const faults::FaultSpec& f : r.schedule.faults) {
    if (f.type == faults::FaultType::LinkCut) {
      throw std::invalid_argument(o.scenario_file + ": line " + std::to_string(f.line) +
                                  ": a link_cut needs the processes in network namespaces; bbw_launch runs them on "
                                  "this host (tests/system/test_failover_netns.cpp carries it out)");
    }
    if (f.type == faults::FaultType::Hang && !r.schedule.standby) {
      throw std::invalid_argument(o.scenario_file + ": line " + std::to_string(f.line) +
                                  ": a CCU hang needs a hot-standby CCU (standby: true or --standby)");
    }
  }
  if (!o.allow_large) scenario::check_run_size(r.scenario);
  for (const auto& a : faults::process_actions(r.schedule)) {
    if (a.target == faults::Target::CCU && a.kind == faults::ProcessAction::Kind::Restart) {
      throw std::invalid_argument(o.scenario_file +
                                  ": restarting the CCU is not supported over DDS (a kill of the CCU ends the run)");
    }
  }
  return r;
}

}  // namespace bbw::launch
