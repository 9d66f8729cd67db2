// One run of a campaign, drawn from the spec by its index alone (pure, seeded: run i is the same
// whatever the run count or the order runs are carried out in), and the scenario file it becomes.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "bbw/faults/schedule.hpp"
#include "spec.hpp"

namespace bbw::campaign {

struct PlannedFault {
  FaultKind kind = FaultKind::Bias;
  Onset onset = Onset::Normal;
  faults::FaultSpec spec;
};

struct RunPlan {
  int index = 0;
  std::uint64_t scenario_seed = 0;
  bool fault_free = true;
  Profile profile = Profile::City;
  double pace = 1.0;                                 // the driver's pace (CampaignSpec::pace_min)
  double duration_s = 0.0;
  int member = 0;                                    // population member
  std::array<double, 4> temperature_C{};             // FL, FR, RL, RR
  std::array<std::string, 4> effect;                 // "" or the plant effect switched on
  std::vector<std::pair<double, double>> demand;     // (t_s, demand 0..1), piecewise linear
  std::vector<std::pair<double, double>> hard_stops; // [start_s, end_s] of each held hard stop
  std::vector<PlannedFault> faults;
};

// The stated detectability limit of a kind (docs/faults.md, "Detectability limits"): a campaign
// draws magnitudes from it up to kind_max_magnitude. Unit: kN (bias), kN/s (drift), kN RMS
// (noise), rev (resolver offset), % (torque loss), ms (delay); 0 for kinds without a magnitude.
double detectability_limit(FaultKind kind);
// Whether an injected fault (its kind's name, magnitude, start and end) is above its kind's
// detectability limit. A drift's limit is a bias's, reached after limit / rate
// (docs/faults.md, "Detectability limits"): one that ends (intermittent, or with the run) before
// its offset reaches the bias limit is not above it, whatever its rate. Kinds without a magnitude
// (stuck, loss, dropout, silence, seized) always are.
bool above_limit(const std::string& kind, double magnitude, double at_s, double end_s);
double kind_max_magnitude(FaultKind kind);

RunPlan draw_run(const CampaignSpec& spec, int index);

// The scenario file of a run (loads with bbw::faults::load_fault_scenario). `plant_file`: the
// base plant (absolute), `name`: the scenario's name.
std::string scenario_yaml(const CampaignSpec& spec, const RunPlan& run, const std::string& plant_file);

}  // namespace bbw::campaign
