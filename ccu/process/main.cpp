// bbw_ccu: the central control unit over Fast DDS: one calibrator per corner, fused clamp-force
// estimates, per-corner commands and calibration states, per-sample logs.
//
//   bbw_ccu --scenario FILE [--domain N] [--mode lockstep|realtime]
//           [--discovery-timeout S] [--peer-timeout S] [--process-faults]
//           [--dds-profiles FILE.xml] [--dds-participant-profile NAME] [--secure KEYS_DIR]
//           [--out DIR] [--calibrator FILE.yaml] [--monitor FILE.yaml] [--friction-feedback on|off]
//           [--standby --role primary|standby]
//
// --standby --role: one of the two CCUs of a run with a hot-standby CCU (issue 16, docs/faults.md
// "Hot-standby CCU"): commands under DDS exclusive ownership, the primary stronger; the standby
// is the participant bbw_ccu_standby (with --secure, identity ccu_standby).
//
// The flags in the first three lines are bbw_corner's too (bbw/runtime/process_cli.hpp).
//
// --secure: DDS Security with the CCU's identity from KEYS_DIR (`./bbw keys KEYS_DIR`,
// docs/security.md); a missing key file is a configuration error (exit 2).
//
// The scenario may carry a fault schedule (docs/faults.md). --process-faults (given by
// bbw_launch, which carries process faults out) makes the CCU freeze at its scheduled kill for
// the launcher to SIGKILL it, and hold the lockstep clock at a corner's scheduled restart.
//
// Exit: 0 done (130/143 when stopped by SIGINT/SIGTERM), 1 runtime or DDS error, 2 bad
// arguments or config, 3 corners not discovered in time, 4 a corner lost or failed.
#include <sys/stat.h>

#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/common/data_path.hpp"
#include "bbw/runtime/process_cli.hpp"
#include "bbw/faults/monitor_yaml.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/runtime/signals.hpp"
#include "bbw/runtime/teardown_guard.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/security/dds_security.hpp"
#include "bbw/vehicle_run/vehicle_scenario.hpp"
#include "ccu_app.hpp"

namespace {

std::string usage() {
  return bbw::runtime::process_usage("bbw_ccu", "", {"[--out DIR] [--calibrator FILE.yaml] [--monitor FILE.yaml] [--friction-feedback on|off]",
                                                  "[--role primary|standby] (with --standby)"});
}

}  // namespace

int main(int argc, char** argv) {
  using namespace bbw::ccu;
  bbw::dds::Events events;
  bbw::runtime::SignalWatcher signals([&](int) { events.interrupt(); });

  CcuOptions opt;
  bbw::runtime::ProcessFlags flags;
  std::string calibrator_file;  // default: config/calibrator/robust.yaml of bbw's data (bbw/common/data_path.hpp)
  std::string monitor_file;     // default: config/faults/monitor.yaml
  bool role_given = false;
  try {
    for (bbw::runtime::ArgCursor args(argc, argv); !args.done();) {
      const std::string k = args.flag();
      if (flags.take(k, args)) continue;
      if (k == "--out") opt.out_dir = args.value();
      else if (k == "--calibrator") calibrator_file = args.value();
      else if (k == "--monitor") monitor_file = args.value();
      else if (k == "--role") {
        opt.role = args.value();
        if (opt.role != "primary" && opt.role != "standby") {
          throw std::invalid_argument("--role must be primary or standby, got '" + opt.role + "'");
        }
        role_given = true;
      }
      else if (k == "--friction-feedback") {
        const std::string v = args.value();
        if (v != "on" && v != "off") throw std::invalid_argument("--friction-feedback must be on or off, got '" + v + "'");
        opt.friction_feedback = v == "on";
      }
      else if (k == "-h" || k == "--help") { std::cout << usage(); return 0; }
      else throw std::invalid_argument("unknown argument '" + k + "'");
    }
    flags.finish(std::getenv("BBW_DOMAIN"));
    if (role_given && !flags.options.standby) throw std::invalid_argument("--role needs --standby (a run with a hot-standby CCU)");
  } catch (const std::exception& e) {
    std::cerr << "bbw_ccu: " << e.what() << "\n" << usage();
    return kExitUsage;
  }
  static_cast<bbw::runtime::ProcessOptions&>(opt) = flags.options;
  const std::string& secure_dir = flags.secure_dir;
  const std::string& scenario_file = flags.scenario_file;

  // Config is loaded and validated before any DDS entity exists.
  std::optional<bbw::scenario::Scenario> scenario;
  std::optional<bbw::vehicle_run::VehicleScenario> vehicle;
  std::optional<bbw::calibration::CalibratorConfig> calibrator;
  try {
    if (!secure_dir.empty()) {
      opt.participant.properties = bbw::security::participant_properties(
          bbw::security::files_for(secure_dir, opt.standby && opt.role == "standby" ? bbw::security::kCcuStandbyIdentity
                                                                                  : bbw::security::kCcuIdentity));
    }
    if (bbw::vehicle_run::is_vehicle_scenario(scenario_file)) {
      // A vehicle scenario (issue 15): its calipers, and the vehicle and pedal as participants.
      vehicle.emplace(bbw::vehicle_run::load_vehicle_scenario(scenario_file));
      if (opt.mode != bbw::runtime::ClockMode::Lockstep) throw std::invalid_argument("a vehicle scenario runs in lockstep only");
      scenario = vehicle->corners.scenario;
      opt.schedule = vehicle->corners.faults;
      opt.vehicle = &*vehicle;
    } else {
      auto fs = bbw::faults::load_fault_scenario(scenario_file);
      scenario = std::move(fs.scenario);
      opt.schedule = std::move(fs.faults);
    }
    if (calibrator_file.empty()) calibrator_file = bbw::data::path("config/calibrator/robust.yaml");
    if (monitor_file.empty()) monitor_file = bbw::data::path("config/faults/monitor.yaml");
    calibrator = bbw::calibration::load_config(calibrator_file);
    calibrator->validate();
    opt.monitor = bbw::faults::load_monitor_params(monitor_file);
    if (!opt.out_dir.empty()) {
      ::mkdir(opt.out_dir.c_str(), 0755);
      struct stat st {};
      if (::stat(opt.out_dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
        throw std::invalid_argument(opt.out_dir + ": cannot create output directory");
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "bbw_ccu: " << e.what() << "\n";
    return kExitUsage;
  }

  int rc = kExitOk;
  std::string error;
  try {
    CcuApp app(*scenario, *calibrator, opt, events);
    std::cout << "bbw_ccu: domain " << opt.participant.domain_id << ", mode " << flags.mode_name << ", scenario "
              << scenario->name << ", " << scenario->corners.size() << " corners" << std::endl;
    rc = app.run(error);
    if (!opt.out_dir.empty()) app.write_stats(opt.out_dir + "/ccu.stats");
    // The results are written; Fast DDS's teardown gets 5 s (teardown_guard.hpp).
    bbw::runtime::bound_teardown("bbw_ccu", std::chrono::milliseconds(5000), rc);
  } catch (const std::invalid_argument& e) {
    std::cerr << "bbw_ccu: " << e.what() << "\n";
    return kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << "bbw_ccu: " << e.what() << "\n";
    return kExitRuntime;
  }
  if (rc != kExitOk) {
    std::cerr << "bbw_ccu: " << error << "\n";
    return rc;
  }
  if (const int sig = signals.received(); sig != 0) return 128 + sig;
  std::cout << "bbw_ccu: done" << std::endl;
  return kExitOk;
}
