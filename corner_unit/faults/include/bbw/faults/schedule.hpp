// A scenario's fault schedule (docs/faults.md): at a simulated time, on a corner or the CCU, a
// fault of one part with its parameters and an optional duration. Plain structs; the YAML
// reader is in bbw/faults/schedule_yaml.hpp.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bbw::faults {

// CCU is the (primary) CCU; CCU_STANDBY the hot-standby CCU of a run with `standby: true`
// (docs/faults.md, "Hot-standby CCU").
enum class Target { FL, FR, RL, RR, CCU, CcuStandby };
enum class Part { LoadCell, Resolver, Actuator, Network, Process };
enum class FaultType {
  Bias,        // load cell: + bias_kN
  Drift,       // load cell: + rate_kN_per_s * (t - at_s)
  Stuck,       // load cell or resolver: the reading freezes at its last value
  NoiseBurst,  // load cell: + Gaussian noise of rms_kN
  Dropout,     // load cell: no value (NaN)
  Offset,      // resolver: + offset_rev
  TorqueLoss,  // actuator: torque_loss_percent of the motor torque is lost
  TotalLoss,   // actuator: no motor torque
  Seized,      // actuator: the mechanism jams; the spindle cannot turn (the brake holds its force)
  Silence,     // network: the corner's messages stop (for duration_s, required)
  Delay,       // network: the corner's messages arrive delay_ms late
  Kill,        // process: the corner (or CCU) process is killed; optionally restarted
  Hang,        // process (a CCU): the process stops (SIGSTOP); continued after resume_after_s if given
  LinkCut,     // network (a CCU): its network link goes down for duration_s (network namespaces only)
};

struct FaultSpec {
  double at_s = 0.0;
  Target target = Target::FL;
  Part part = Part::LoadCell;
  FaultType type = FaultType::Bias;
  std::optional<double> duration_s;     // absent: until the end of the run
  // Parameters; each type uses only its own (the others stay 0 / empty).
  double bias_kN = 0.0;
  double rate_kN_per_s = 0.0;
  double rms_kN = 0.0;
  double offset_rev = 0.0;
  double torque_loss_percent = 0.0;
  double delay_ms = 0.0;
  std::optional<double> restart_after_s;  // process kill
  std::optional<double> resume_after_s;   // process hang (absent: hung to the end)
  int line = 0;                           // where it was read from (0 when built in code)

  // Active in [at_s, at_s + duration_s); a kill is active until the restart (if any).
  bool active_at(double time_s) const;
  double end_s() const;  // +inf when it never ends
};

struct FaultSchedule {
  std::vector<FaultSpec> faults;  // in file order
  // Top-level `standby: true`: the run has a hot-standby CCU (docs/faults.md). Read with the
  // schedule because it changes which process faults make sense (CCU_STANDBY, hang, link_cut).
  bool standby = false;
  // The faults of one target, in file order (allocates; call at set-up).
  std::vector<FaultSpec> for_target(Target t) const;
  bool empty() const { return faults.empty(); }
};

// The processes a four-corner run starts: the scenario's declared `processes:` list, or else
// `ccu`, `ccu_standby` with `standby: true`, and the scenario's corners in scenario order.
std::vector<std::string> run_processes(const std::vector<std::string>& declared, const std::vector<std::string>& scenario_corners,
                                       const FaultSchedule& schedule);

const char* to_string(Target t);
const char* to_string(Part p);
const char* to_string(FaultType t);
// "FL" -> Target::FL ...; nullopt for anything else.
std::optional<Target> target_from_name(std::string_view name);
// CCU or CCU_STANDBY.
inline bool is_ccu(Target t) { return t == Target::CCU || t == Target::CcuStandby; }
// The corner index of FL/FR/RL/RR in that order (the CCU has none).
std::optional<std::size_t> corner_slot(Target t);
// Which part a type belongs to (Stuck belongs to both sensors: nullopt).
std::optional<Part> part_of(FaultType t);

}  // namespace bbw::faults
