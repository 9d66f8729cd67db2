// A scenario: what to simulate, for how long, with which plant, and what each corner does.
// Plain structs; the YAML loader is in bbw/scenario/load.hpp, the per-corner simulation in
// bbw/scenario/corner_sim.hpp. The schema is documented in docs/plant.md ("Scenario files").
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bbw/corner_unit/controller.hpp"
#include "bbw/plant/params.hpp"
#include "bbw/scenario/profile.hpp"

namespace bbw::scenario {

enum class Axle { Front, Rear };
enum class DriveMode {
  Position,  // follow a position profile (test rig)
  Force,     // follow a clamp-force breakpoint profile
  Demand,    // clamp force from the scenario's pedal demand and this corner's axle
};

struct DriveSpec {
  DriveMode mode = DriveMode::Position;
  PositionProfileSpec position;                 // mode Position
  std::vector<Breakpoint> force_kN;             // mode Force: [t_s, force_kN]
  corner_unit::ForceFeedback feedback = corner_unit::ForceFeedback::LoadCell;  // Force, Demand
};

// Vehicle pedal demand: fraction of full braking over time, split front/rear.
// Front corners get demand * max_clamp_force_kN; rear corners get that times
// (1 - front_share) / front_share, so the front axle carries front_share of the total.
struct DemandSpec {
  double max_clamp_force_kN = 40.0;
  double front_share = 0.6;                     // in [0.5, 0.9]
  std::vector<Breakpoint> profile;              // [t_s, demand in 0..1]

  double axle_factor(Axle axle) const {
    return axle == Axle::Front ? 1.0 : (1.0 - front_share) / front_share;
  }
};

struct CornerSpec {
  std::string name;                             // free text offline; FL/FR/RL/RR over DDS
  int line = 0;                                 // line of its entry in the file (0 if built in code)
  std::optional<Axle> axle;                     // given, or inferred from FL/FR/RL/RR
  plant::Conditions conditions;                 // temperature (and its ramp), wear
  plant::EffectsParams effects;                 // all off unless the file switches them on
  plant::SensorParams sensors;                  // the plant file's, with this corner's overrides
  DriveSpec drive;
};

struct Scenario {
  std::string name;
  std::string file;                             // the file it was loaded from ("" if built in code)
  std::uint64_t seed = 1;
  double duration_s = 10.0;
  int duration_line = 0;
  // Top-level `processes:` (optional; ./bbw run): the processes of the run as the launcher
  // starts them, `ccu`, `ccu_standby` and each corner once (checked against the corners and the
  // standby key with the fault schedule, bbw/faults/schedule_yaml.hpp). Empty when not declared.
  std::vector<std::string> processes;
  int processes_line = 0;                        // line of duration_s in the file (0 if built in code)
  double plant_dt_s = 0.001;
  double ccu_period_s = 0.005;                  // used by the DDS system
  std::string plant_file;                       // resolved path of the plant parameter file
  plant::PlantParams plant;
  corner_unit::ControllerParams controller;     // gains; actuator model derived from plant
  std::optional<DemandSpec> demand;
  std::vector<CornerSpec> corners;
};

// The controller's nominal actuator model computed from plant parameters.
corner_unit::ActuatorModel actuator_model(const plant::PlantParams& plant);
// The noise seed of corner `index` derived from the scenario seed (SplitMix64 of both).
std::uint64_t corner_seed(std::uint64_t scenario_seed, std::size_t index);
// Axle from a corner name: "FL"/"FR" front, "RL"/"RR" rear, otherwise nullopt.
std::optional<Axle> axle_from_name(const std::string& name);

}  // namespace bbw::scenario
