#include "bbw/scenario/scenario.hpp"

namespace bbw::scenario {

corner_unit::ActuatorModel actuator_model(const plant::PlantParams& p) {
  constexpr double kTwoPi = 6.283185307179586;
  corner_unit::ActuatorModel a;
  const auto& t = p.transmission;
  a.torque_per_A_Nm = p.motor.torque_constant_Nm_per_A * t.gear_ratio * t.efficiency;
  a.Nm_per_kN = 1000.0 * t.lead_mm_per_rev * 1.0e-3 / kTwoPi;
  a.inertia_kg_m2 = p.motor.rotor_inertia_kg_m2 * t.gear_ratio * t.gear_ratio + t.spindle_inertia_kg_m2;
  return a;
}

std::uint64_t corner_seed(std::uint64_t scenario_seed, std::size_t index) {
  std::uint64_t z = scenario_seed + 0x9E3779B97F4A7C15ull * (static_cast<std::uint64_t>(index) + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

std::optional<Axle> axle_from_name(const std::string& name) {
  if (name == "FL" || name == "FR") return Axle::Front;
  if (name == "RL" || name == "RR") return Axle::Rear;
  return std::nullopt;
}

}  // namespace bbw::scenario
