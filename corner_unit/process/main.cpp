// bbw_corner: one e-caliper process (plant, sensors, local controller) over Fast DDS.
//
//   bbw_corner --corner FL|FR|RL|RR --scenario FILE [--domain N] [--mode lockstep|realtime]
//              [--discovery-timeout S] [--peer-timeout S] [--process-faults]
//              [--dds-profiles FILE.xml] [--dds-participant-profile NAME] [--secure KEYS_DIR]
//              [--stats FILE] [--periods-log FILE] [--incarnation N --resume-at S]
//
// The flags from --scenario to --secure are bbw_ccu's too (bbw/runtime/process_cli.hpp).
//
// --secure: DDS Security with this corner's identity from KEYS_DIR (`./bbw keys KEYS_DIR`,
// docs/security.md); a missing key file is a configuration error (exit 2).
//
// The scenario may carry a fault schedule (docs/faults.md): this corner's sensor, actuator and
// network faults are injected here. --process-faults (given by bbw_launch) makes the corner
// freeze at its scheduled kill for the launcher to SIGKILL it; --incarnation/--resume-at start
// a restarted corner at the scenario time it rejoins.
//
// Exit: 0 done (or stopped by SIGINT/SIGTERM: 130/143), 1 runtime or DDS error, 2 bad
// arguments or config, 3 CCU not discovered in time, 4 CCU lost (no command in time).
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "bbw/common/strict_yaml.hpp"
#include "bbw/runtime/teardown_guard.hpp"
#include "bbw/runtime/process_cli.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/runtime/signals.hpp"
#include "bbw/runtime/stats_file.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/security/dds_security.hpp"
#include "bbw/vehicle_run/vehicle_scenario.hpp"
#include "corner_app.hpp"

namespace {

std::string usage() {
  return bbw::runtime::process_usage("bbw_corner", "--corner FL|FR|RL|RR",
                                {"[--stats FILE] [--periods-log FILE] [--incarnation N --resume-at S]"});
}

}  // namespace

int main(int argc, char** argv) {
  using namespace bbw::corner_process;
  bbw::dds::Events events;
  bbw::runtime::SignalWatcher signals([&](int) { events.interrupt(); });

  CornerOptions opt;
  bbw::runtime::ProcessFlags flags;
  std::string corner_arg;
  try {
    for (bbw::runtime::ArgCursor args(argc, argv); !args.done();) {
      const std::string k = args.flag();
      if (flags.take(k, args)) continue;
      if (k == "--corner") corner_arg = args.value();
      else if (k == "--stats") opt.stats_file = args.value();
      else if (k == "--periods-log") opt.periods_log = args.value();
      else if (k == "--incarnation") {
        const std::string v = args.value();
        char* end = nullptr;
        const unsigned long n = std::strtoul(v.c_str(), &end, 10);
        if (v.empty() || *end != '\0' || n > 1000) throw std::invalid_argument("--incarnation must be 0..1000, got '" + v + "'");
        opt.incarnation = static_cast<std::uint32_t>(n);
      } else if (k == "--resume-at") {
        const std::string v = args.value();
        char* end = nullptr;
        opt.resume_at_s = std::strtod(v.c_str(), &end);
        if (v.empty() || *end != '\0' || !(opt.resume_at_s >= 0.0)) throw std::invalid_argument("--resume-at must be seconds >= 0, got '" + v + "'");
      }
      else if (k == "-h" || k == "--help") { std::cout << usage(); return 0; }
      else throw std::invalid_argument("unknown argument '" + k + "'");
    }
    if (corner_arg.empty()) throw std::invalid_argument("--corner is required");
    flags.finish(std::getenv("BBW_DOMAIN"));
    const auto corner = bbw::dds::parse_corner(corner_arg);
    if (!corner) throw std::invalid_argument("unknown corner '" + corner_arg + "' (expected FL, FR, RL or RR)");
    opt.corner = *corner;
  } catch (const std::exception& e) {
    std::cerr << "bbw_corner: " << e.what() << "\n" << usage();
    return kExitUsage;
  }
  static_cast<bbw::runtime::ProcessOptions&>(opt) = flags.options;
  const std::string& secure_dir = flags.secure_dir;
  const std::string& scenario_file = flags.scenario_file;

  // Config is loaded and validated before any DDS entity exists.
  std::optional<bbw::scenario::Scenario> scenario;
  try {
    if (!secure_dir.empty()) {
      opt.participant.properties = bbw::security::participant_properties(
          bbw::security::files_for(secure_dir, bbw::security::corner_identity(corner_arg)));
    }
    if (bbw::vehicle_run::is_vehicle_scenario(scenario_file)) {
      // A vehicle scenario (issue 15): this corner's caliper; its temperature from the vehicle.
      auto vs = bbw::vehicle_run::load_vehicle_scenario(scenario_file);
      if (opt.mode != bbw::runtime::ClockMode::Lockstep) throw std::invalid_argument("a vehicle scenario runs in lockstep only");
      scenario = std::move(vs.corners.scenario);
      opt.schedule = std::move(vs.corners.faults);
      opt.vehicle = true;
    } else {
      auto fs = bbw::faults::load_fault_scenario(scenario_file);
      scenario = std::move(fs.scenario);
      opt.schedule = std::move(fs.faults);
    }
    bool found = false;
    for (std::size_t i = 0; i < scenario->corners.size(); ++i) {
      if (scenario->corners[i].name == corner_arg) {
        opt.scenario_index = i;
        found = true;
      }
    }
    if (!found) {
      std::string names;
      for (const auto& c : scenario->corners) names += (names.empty() ? "" : ", ") + c.name;
      throw std::invalid_argument(scenario_file + ": has no corner " + corner_arg + " (it has " + names + ")");
    }
  } catch (const std::exception& e) {
    std::cerr << "bbw_corner " << corner_arg << ": " << e.what() << "\n";
    return kExitUsage;
  }

  int rc = kExitOk;
  std::string error;
  try {
    // With security: a new participant when the CCU has not matched within 5 s (see
    // CornerOptions::match_timeout), until the discovery deadline.
    const auto discovery_deadline = std::chrono::steady_clock::now() + opt.discovery_timeout;
    std::unique_ptr<CornerApp> app;
    for (int attempt = 1;; ++attempt) {
      const auto remaining = std::chrono::duration_cast<std::chrono::milliseconds>(
          discovery_deadline - std::chrono::steady_clock::now());
      CornerOptions o = opt;
      const bool retry = !secure_dir.empty() && remaining > std::chrono::milliseconds(6000);
      o.match_timeout = retry ? std::chrono::milliseconds(5000) : std::max(remaining, std::chrono::milliseconds(1));
      app.reset();  // the old participant goes before the new one exists
      app = std::make_unique<CornerApp>(*scenario, o, events);
      if (attempt == 1) {
        std::cout << "bbw_corner " << corner_arg << ": domain " << opt.participant.domain_id << ", mode " << flags.mode_name
                  << ", scenario " << scenario->name << std::endl;
      }
      rc = app->run(error);
      if (!(retry && rc == kExitDiscovery && !app->matched_ccu() && !events.interrupted())) break;
      std::cerr << "bbw_corner " << corner_arg << ": CCU not matched within 5 s (attempt " << attempt
                << "), joining again with a new participant" << std::endl;
    }
    if (!opt.stats_file.empty()) app->write_stats(opt.stats_file);
    std::cout << "bbw_corner " << corner_arg << ": " << app->stats().periods << " periods, "
              << app->stats().samples_published << " samples published" << std::endl;
    // The results are written; Fast DDS's teardown gets 5 s (teardown_guard.hpp).
    bbw::runtime::bound_teardown("bbw_corner " + corner_arg, std::chrono::milliseconds(5000), rc);
  } catch (const std::invalid_argument& e) {
    std::cerr << "bbw_corner " << corner_arg << ": " << e.what() << "\n";
    return kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << "bbw_corner " << corner_arg << ": " << e.what() << "\n";
    return kExitRuntime;
  }
  if (rc != kExitOk) {
    std::cerr << "bbw_corner " << corner_arg << ": " << error << "\n";
    return rc;
  }
  if (const int sig = signals.received(); sig != 0) return 128 + sig;
  return kExitOk;
}
