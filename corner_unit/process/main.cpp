// bbw_corner: one e-caliper process (plant, sensors, local controller) over Fast DDS.
//
//   bbw_corner --corner FL|FR|RL|RR --scenario FILE [--domain N] [--mode lockstep|realtime]
//              [--stats FILE] [--discovery-timeout S] [--peer-timeout S]
//              [--dds-profiles FILE.xml] [--dds-participant-profile NAME]
//              [--periods-log FILE] [--process-faults] [--incarnation N --resume-at S]
//              [--secure KEYS_DIR]
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
#include "bbw/dds/domain.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/launch/signals.hpp"
#include "bbw/launch/stats_file.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/security/dds_security.hpp"
#include "corner_app.hpp"

namespace {

const char* kUsage =
    "usage: bbw_corner --corner FL|FR|RL|RR --scenario FILE [--domain N] [--mode lockstep|realtime]\n"
    "                  [--stats FILE] [--discovery-timeout S] [--peer-timeout S]\n"
    "                  [--dds-profiles FILE.xml] [--dds-participant-profile NAME]\n"
    "                  [--periods-log FILE] [--process-faults] [--incarnation N --resume-at S]\n"
    "                  [--secure KEYS_DIR]\n";

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
  using namespace bbw::corner_process;
  bbw::dds::Events events;
  bbw::launch::SignalWatcher signals([&](int) { events.interrupt(); });

  CornerOptions opt;
  std::string corner_arg, scenario_file, mode = "lockstep", secure_dir;
  std::optional<std::string> domain_arg;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string k = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument("missing value after " + k);
        return argv[++i];
      };
      if (k == "--corner") corner_arg = next();
      else if (k == "--scenario") scenario_file = next();
      else if (k == "--domain") domain_arg = next();
      else if (k == "--mode") mode = next();
      else if (k == "--stats") opt.stats_file = next();
      else if (k == "--discovery-timeout") opt.discovery_timeout = seconds_arg(k, next());
      else if (k == "--peer-timeout") opt.peer_timeout = seconds_arg(k, next());
      else if (k == "--dds-profiles") opt.participant.profiles_file = next();
      else if (k == "--dds-participant-profile") opt.participant.profile = next();
      else if (k == "--periods-log") opt.periods_log = next();
      else if (k == "--secure") secure_dir = next();
      else if (k == "--process-faults") opt.process_faults = true;
      else if (k == "--incarnation") {
        const std::string v = next();
        char* end = nullptr;
        const unsigned long n = std::strtoul(v.c_str(), &end, 10);
        if (v.empty() || *end != '\0' || n > 1000) throw std::invalid_argument("--incarnation must be 0..1000, got '" + v + "'");
        opt.incarnation = static_cast<std::uint32_t>(n);
      } else if (k == "--resume-at") {
        const std::string v = next();
        char* end = nullptr;
        opt.resume_at_s = std::strtod(v.c_str(), &end);
        if (v.empty() || *end != '\0' || !(opt.resume_at_s >= 0.0)) throw std::invalid_argument("--resume-at must be seconds >= 0, got '" + v + "'");
      }
      else if (k == "-h" || k == "--help") { std::cout << kUsage; return 0; }
      else throw std::invalid_argument("unknown argument '" + k + "'");
    }
    if (corner_arg.empty()) throw std::invalid_argument("--corner is required");
    if (scenario_file.empty()) throw std::invalid_argument("--scenario is required");
    const auto corner = bbw::dds::parse_corner(corner_arg);
    if (!corner) throw std::invalid_argument("unknown corner '" + corner_arg + "' (expected FL, FR, RL or RR)");
    opt.corner = *corner;
    if (mode == "lockstep") opt.mode = ClockMode::Lockstep;
    else if (mode == "realtime") opt.mode = ClockMode::Realtime;
    else throw std::invalid_argument("--mode must be lockstep or realtime, got '" + mode + "'");
    opt.participant.domain_id = bbw::dds::resolve_domain_id(domain_arg, std::getenv("BBW_DOMAIN"));
  } catch (const std::exception& e) {
    std::cerr << "bbw_corner: " << e.what() << "\n" << kUsage;
    return kExitUsage;
  }

  // Config is loaded and validated before any DDS entity exists.
  std::optional<bbw::scenario::Scenario> scenario;
  try {
    if (!secure_dir.empty()) {
      opt.participant.properties = bbw::security::participant_properties(
          bbw::security::files_for(secure_dir, bbw::security::corner_identity(corner_arg)));
    }
    auto fs = bbw::faults::load_fault_scenario(scenario_file);
    scenario = std::move(fs.scenario);
    opt.schedule = std::move(fs.faults);
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
        std::cout << "bbw_corner " << corner_arg << ": domain " << opt.participant.domain_id << ", mode " << mode
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
