#include "bbw/faults/schedule_yaml.hpp"

#include <algorithm>

namespace bbw::faults {
namespace {

using config::Range;

const std::vector<std::string> kTargets = {"FL", "FR", "RL", "RR", "CCU", "CCU_STANDBY"};
const std::vector<std::string> kParts = {"load_cell", "resolver", "actuator", "network", "process"};

Part part_from(const std::string& s) {
  if (s == "load_cell") return Part::LoadCell;
  if (s == "resolver") return Part::Resolver;
  if (s == "actuator") return Part::Actuator;
  if (s == "network") return Part::Network;
  return Part::Process;
}

// The types each part accepts, in the order the docs list them. A CCU (primary or standby)
// fails only as a process (kill, hang) or by its link (link_cut); a corner never hangs or has
// its link cut (silence is the corner's link fault).
std::vector<std::string> types_of(Part p, bool ccu) {
  if (ccu) return p == Part::Network ? std::vector<std::string>{"link_cut"} : std::vector<std::string>{"kill", "hang"};
  switch (p) {
    case Part::LoadCell: return {"bias", "drift", "stuck", "noise_burst", "dropout"};
    case Part::Resolver: return {"offset", "stuck"};
    case Part::Actuator: return {"torque_loss", "total_loss", "seized"};
    case Part::Network: return {"silence", "delay"};
    case Part::Process: return {"kill"};
  }
  return {};
}

FaultType type_from(const std::string& s) {
  if (s == "bias") return FaultType::Bias;
  if (s == "drift") return FaultType::Drift;
  if (s == "stuck") return FaultType::Stuck;
  if (s == "noise_burst") return FaultType::NoiseBurst;
  if (s == "dropout") return FaultType::Dropout;
  if (s == "offset") return FaultType::Offset;
  if (s == "torque_loss") return FaultType::TorqueLoss;
  if (s == "total_loss") return FaultType::TotalLoss;
  if (s == "seized") return FaultType::Seized;
  if (s == "silence") return FaultType::Silence;
  if (s == "delay") return FaultType::Delay;
  if (s == "hang") return FaultType::Hang;
  if (s == "link_cut") return FaultType::LinkCut;
  return FaultType::Kill;
}

double nonzero(config::Reader& r, const std::string& key) {
  const double v = r.number(key);
  if (v == 0.0) r.fail(key, "must not be 0 (a fault that changes nothing)");
  return v;
}

FaultSpec read_one(config::Reader& r) {
  FaultSpec f;
  f.line = r.line();
  f.at_s = r.number("at_s", Range::non_negative());
  f.target = *target_from_name(r.choice("corner", kTargets));
  f.part = part_from(r.choice("part", kParts));
  if (is_ccu(f.target) && f.part != Part::Process && f.part != Part::Network) {
    r.fail("part", "a CCU can only fail as a process (part: process, type: kill or hang) or by its link (part: network, type: link_cut)");
  }
  f.type = type_from(r.choice("type", types_of(f.part, is_ccu(f.target))));
  switch (f.type) {
    case FaultType::Bias: f.bias_kN = nonzero(r, "bias_kN"); break;
    case FaultType::Drift: f.rate_kN_per_s = nonzero(r, "rate_kN_per_s"); break;
    case FaultType::NoiseBurst: f.rms_kN = r.number("rms_kN", Range::positive()); break;
    case FaultType::Offset: f.offset_rev = nonzero(r, "offset_rev"); break;
    case FaultType::TorqueLoss:
      f.torque_loss_percent = r.number("loss_percent", Range{0.0, 100.0, true, true});
      break;
    case FaultType::Delay: f.delay_ms = r.number("delay_ms", Range::positive()); break;
    case FaultType::Kill:
      if (r.has("restart_after_s")) f.restart_after_s = r.number("restart_after_s", Range::positive());
      if (r.has("duration_s")) r.fail("duration_s", "a kill lasts until the restart: use restart_after_s");
      if (f.restart_after_s && is_ccu(f.target)) {
        r.fail("restart_after_s", "a CCU is not restarted over DDS (a killed CCU stays dead; a hung one may resume: type hang, resume_after_s)");
      }
      break;
    case FaultType::Hang:
      if (r.has("resume_after_s")) f.resume_after_s = r.number("resume_after_s", Range::positive());
      if (r.has("duration_s")) r.fail("duration_s", "a hang lasts until it is resumed: use resume_after_s");
      break;
    case FaultType::LinkCut:
    case FaultType::Stuck:
    case FaultType::Dropout:
    case FaultType::TotalLoss:
    case FaultType::Seized:
    case FaultType::Silence: break;
  }
  if (f.type == FaultType::Silence && !r.has("duration_s")) r.fail("duration_s", "required key is missing (silence)");
  if (f.type != FaultType::Kill && f.type != FaultType::Hang && r.has("duration_s")) f.duration_s = r.number("duration_s", Range::positive());
  r.finish();
  return f;
}

// The declared `processes:` against the scenario: ccu once, ccu_standby exactly when the run has
// a standby, every corner of the scenario and no other.
void check_processes(const scenario::Scenario& s, const FaultSchedule& faults, const std::string& file) {
  if (s.processes.empty()) return;
  const int line = s.processes_line;
  std::vector<std::string> seen;
  for (const std::string& p : s.processes) {
    if (std::find(seen.begin(), seen.end(), p) != seen.end()) {
      throw config::ConfigError(file, line, "processes", "'" + p + "' is listed twice");
    }
    seen.push_back(p);
    if (p == "vehicle" || p == "pedal") {
      throw config::ConfigError(file, line, "processes",
                                "'" + p + "' runs in a vehicle scenario only (config/scenarios/vehicle/)");
    }
    if (p == "ccu" || p == "ccu_standby") continue;
    if (!target_from_name(p) || is_ccu(*target_from_name(p))) {
      throw config::ConfigError(file, line, "processes",
                                "unknown process '" + p + "' (ccu, ccu_standby, FL, FR, RL, RR)");
    }
    const bool in_scenario = std::any_of(s.corners.begin(), s.corners.end(),
                                         [&](const scenario::CornerSpec& c) { return c.name == p; });
    if (!in_scenario) throw config::ConfigError(file, line, "processes", "no corner named " + p + " in this scenario");
  }
  if (std::find(seen.begin(), seen.end(), "ccu") == seen.end()) {
    throw config::ConfigError(file, line, "processes", "a run needs its CCU: list ccu");
  }
  for (const auto& c : s.corners) {
    if (std::find(seen.begin(), seen.end(), c.name) == seen.end()) {
      throw config::ConfigError(file, line, "processes",
                                "corner " + c.name + " of this scenario has no process: list it (each corner runs as one)");
    }
  }
  const bool listed_standby = std::find(seen.begin(), seen.end(), "ccu_standby") != seen.end();
  if (listed_standby != faults.standby) {
    throw config::ConfigError(file, line, "processes",
                              faults.standby ? "standby: true runs a hot-standby CCU: list ccu_standby"
                                             : "ccu_standby needs standby: true (a hot-standby run)");
  }
}

void check_against(const scenario::Scenario& s, const FaultSchedule& faults, const std::string& file) {
  check_processes(s, faults, file);
  for (std::size_t i = 0; i < faults.faults.size(); ++i) {
    const FaultSpec& f = faults.faults[i];
    const std::string at = "faults[" + std::to_string(i) + "]";
    if (f.target == Target::CcuStandby && !faults.standby) {
      throw config::ConfigError(file, f.line, at + ".corner", "CCU_STANDBY needs a standby CCU (top-level standby: true)");
    }
    if (!is_ccu(f.target)) {
      const bool found = std::any_of(s.corners.begin(), s.corners.end(),
                                     [&](const scenario::CornerSpec& c) { return c.name == to_string(f.target); });
      if (!found) {
        throw config::ConfigError(file, f.line, at + ".corner",
                                  std::string("no corner named ") + to_string(f.target) + " in this scenario");
      }
    }
    if (!(f.at_s < s.duration_s)) {
      throw config::ConfigError(file, f.line, at + ".at_s",
                                "must be before the scenario ends (" + std::to_string(s.duration_s) + " s)");
    }
  }
}

}  // namespace

FaultSchedule read_fault_schedule(config::Reader& top) {
  FaultSchedule out;
  out.standby = top.boolean_or("standby", false);
  if (!top.has("faults")) {
    (void)top.optional_map("faults");  // marks an explicit `faults:` (null) as known
    return out;
  }
  for (auto& r : top.maps("faults")) out.faults.push_back(read_one(r));
  return out;
}

scenario::ExtraKeys fault_schedule_reader(FaultSchedule& out) {
  return [&out](config::Reader& top) { out = read_fault_schedule(top); };
}

void check_schedule(const scenario::Scenario& s, const FaultSchedule& faults) { check_against(s, faults, s.file); }

FaultScenario load_fault_scenario(const std::string& file) {
  FaultScenario out;
  out.scenario = scenario::load_scenario(file, fault_schedule_reader(out.faults));
  check_against(out.scenario, out.faults, file);
  return out;
}

FaultScenario load_fault_scenario_string(const std::string& text, const std::string& name) {
  FaultScenario out;
  out.scenario = scenario::load_scenario_string(text, name, fault_schedule_reader(out.faults));
  check_against(out.scenario, out.faults, name);
  return out;
}

}  // namespace bbw::faults
