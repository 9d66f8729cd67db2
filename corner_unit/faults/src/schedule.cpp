#include "bbw/faults/schedule.hpp"

#include <limits>

namespace bbw::faults {

double FaultSpec::end_s() const {
  if (type == FaultType::Kill) {
    return restart_after_s ? at_s + *restart_after_s : std::numeric_limits<double>::infinity();
  }
  if (type == FaultType::Hang) {
    return resume_after_s ? at_s + *resume_after_s : std::numeric_limits<double>::infinity();
  }
  return duration_s ? at_s + *duration_s : std::numeric_limits<double>::infinity();
}

bool FaultSpec::active_at(double time_s) const { return time_s >= at_s && time_s < end_s(); }

std::vector<FaultSpec> FaultSchedule::for_target(Target t) const {
  std::vector<FaultSpec> out;
  for (const auto& f : faults) {
    if (f.target == t) out.push_back(f);
  }
  return out;
}

std::vector<std::string> run_processes(const std::vector<std::string>& declared, const std::vector<std::string>& scenario_corners,
                                       const FaultSchedule& schedule) {
  if (!declared.empty()) return declared;
  std::vector<std::string> out{"ccu"};
  if (schedule.standby) out.emplace_back("ccu_standby");
  out.insert(out.end(), scenario_corners.begin(), scenario_corners.end());
  return out;
}

const char* to_string(Target t) {
  switch (t) {
    case Target::FL: return "FL";
    case Target::FR: return "FR";
    case Target::RL: return "RL";
    case Target::RR: return "RR";
    case Target::CCU: return "CCU";
    case Target::CcuStandby: return "CCU_STANDBY";
  }
  return "?";
}

const char* to_string(Part p) {
  switch (p) {
    case Part::LoadCell: return "load_cell";
    case Part::Resolver: return "resolver";
    case Part::Actuator: return "actuator";
    case Part::Network: return "network";
    case Part::Process: return "process";
  }
  return "?";
}

const char* to_string(FaultType t) {
  switch (t) {
    case FaultType::Bias: return "bias";
    case FaultType::Drift: return "drift";
    case FaultType::Stuck: return "stuck";
    case FaultType::NoiseBurst: return "noise_burst";
    case FaultType::Dropout: return "dropout";
    case FaultType::Offset: return "offset";
    case FaultType::TorqueLoss: return "torque_loss";
    case FaultType::TotalLoss: return "total_loss";
    case FaultType::Seized: return "seized";
    case FaultType::Silence: return "silence";
    case FaultType::Delay: return "delay";
    case FaultType::Kill: return "kill";
    case FaultType::Hang: return "hang";
    case FaultType::LinkCut: return "link_cut";
  }
  return "?";
}

std::optional<Target> target_from_name(std::string_view name) {
  if (name == "FL") return Target::FL;
  if (name == "FR") return Target::FR;
  if (name == "RL") return Target::RL;
  if (name == "RR") return Target::RR;
  if (name == "CCU") return Target::CCU;
  if (name == "CCU_STANDBY") return Target::CcuStandby;
  return std::nullopt;
}

std::optional<std::size_t> corner_slot(Target t) {
  switch (t) {
    case Target::FL: return 0;
    case Target::FR: return 1;
    case Target::RL: return 2;
    case Target::RR: return 3;
    case Target::CCU:
    case Target::CcuStandby: return std::nullopt;
  }
  return std::nullopt;
}

std::optional<Part> part_of(FaultType t) {
  switch (t) {
    case FaultType::Bias:
    case FaultType::Drift:
    case FaultType::NoiseBurst:
    case FaultType::Dropout: return Part::LoadCell;
    case FaultType::Offset: return Part::Resolver;
    case FaultType::TorqueLoss:
    case FaultType::TotalLoss:
    case FaultType::Seized: return Part::Actuator;
    case FaultType::Silence:
    case FaultType::Delay:
    case FaultType::LinkCut: return Part::Network;
    case FaultType::Kill:
    case FaultType::Hang: return Part::Process;
    case FaultType::Stuck: return std::nullopt;
  }
  return std::nullopt;
}

}  // namespace bbw::faults
