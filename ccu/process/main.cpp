// bbw_ccu: the central control unit over Fast DDS: one calibrator per corner, fused clamp-force
// estimates, per-corner commands and calibration states, per-sample logs.
//
//   bbw_ccu --scenario FILE [--domain N] [--mode lockstep|realtime] [--out DIR]
//           [--calibrator FILE.yaml] [--friction-feedback on|off]
//           [--discovery-timeout S] [--peer-timeout S]
//           [--dds-profiles FILE.xml] [--dds-participant-profile NAME] [--process-faults]
//           [--secure KEYS_DIR]
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
#include "bbw/dds/domain.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/launch/signals.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/security/dds_security.hpp"
#include "ccu_app.hpp"

namespace {

const char* kUsage =
    "usage: bbw_ccu --scenario FILE [--domain N] [--mode lockstep|realtime] [--out DIR]\n"
    "               [--calibrator FILE.yaml] [--friction-feedback on|off]\n"
    "               [--discovery-timeout S] [--peer-timeout S]\n"
    "               [--dds-profiles FILE.xml] [--dds-participant-profile NAME] [--process-faults]\n"
    "               [--secure KEYS_DIR]\n";

std::chrono::milliseconds seconds_arg(const std::string& key, const std::string& v) {
  char* end = nullptr;
  const double s = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || !(s > 0.0) || s > 3600.0) {
    throw std::invalid_argument(key + " must be a number of seconds in (0, 3600], got '" + v + "'");
  }
  return std::chrono::milliseconds(static_cast<long long>(s * 1000.0));
}

}  // namespace

int main(int argc, char** argv) {
  using namespace bbw::ccu;
  bbw::dds::Events events;
  bbw::launch::SignalWatcher signals([&](int) { events.interrupt(); });

  CcuOptions opt;
  std::string scenario_file, mode = "lockstep", calibrator_file = BBW_DEFAULT_CALIBRATOR_CONFIG, secure_dir;
  std::optional<std::string> domain_arg;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string k = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument("missing value after " + k);
        return argv[++i];
      };
      if (k == "--scenario") scenario_file = next();
      else if (k == "--domain") domain_arg = next();
      else if (k == "--mode") mode = next();
      else if (k == "--out") opt.out_dir = next();
      else if (k == "--calibrator") calibrator_file = next();
      else if (k == "--friction-feedback") {
        const std::string v = next();
        if (v != "on" && v != "off") throw std::invalid_argument("--friction-feedback must be on or off, got '" + v + "'");
        opt.friction_feedback = v == "on";
      }
      else if (k == "--discovery-timeout") opt.discovery_timeout = seconds_arg(k, next());
      else if (k == "--peer-timeout") opt.peer_timeout = seconds_arg(k, next());
      else if (k == "--dds-profiles") opt.participant.profiles_file = next();
      else if (k == "--dds-participant-profile") opt.participant.profile = next();
      else if (k == "--process-faults") opt.process_faults = true;
      else if (k == "--secure") secure_dir = next();
      else if (k == "-h" || k == "--help") { std::cout << kUsage; return 0; }
      else throw std::invalid_argument("unknown argument '" + k + "'");
    }
    if (scenario_file.empty()) throw std::invalid_argument("--scenario is required");
    if (mode == "lockstep") opt.mode = ClockMode::Lockstep;
    else if (mode == "realtime") opt.mode = ClockMode::Realtime;
    else throw std::invalid_argument("--mode must be lockstep or realtime, got '" + mode + "'");
    opt.participant.domain_id = bbw::dds::resolve_domain_id(domain_arg, std::getenv("BBW_DOMAIN"));
  } catch (const std::exception& e) {
    std::cerr << "bbw_ccu: " << e.what() << "\n" << kUsage;
    return kExitUsage;
  }

  // Config is loaded and validated before any DDS entity exists.
  std::optional<bbw::scenario::Scenario> scenario;
  std::optional<bbw::calibration::CalibratorConfig> calibrator;
  try {
    if (!secure_dir.empty()) {
      opt.participant.properties = bbw::security::participant_properties(
          bbw::security::files_for(secure_dir, bbw::security::kCcuIdentity));
    }
    auto fs = bbw::faults::load_fault_scenario(scenario_file);
    scenario = std::move(fs.scenario);
    opt.schedule = std::move(fs.faults);
    calibrator = bbw::calibration::load_config(calibrator_file);
    calibrator->validate();
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
    std::cout << "bbw_ccu: domain " << opt.participant.domain_id << ", mode " << mode << ", scenario "
              << scenario->name << ", " << scenario->corners.size() << " corners" << std::endl;
    rc = app.run(error);
    if (!opt.out_dir.empty()) app.write_stats(opt.out_dir + "/ccu.stats");
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
