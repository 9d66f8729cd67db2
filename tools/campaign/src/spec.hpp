// A fault campaign's spec (config/campaigns/*.yaml; docs/faults.md, "Campaigns"): how many runs,
// which share is fault-free, the caliper population, driving profiles, temperatures, plant
// effects and the faults to draw. Loaded strictly (file, line, key path and rule on any error).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace bbw::campaign {

// Driving profiles (demand over time; draw.cpp builds them).
enum class Profile { City, Abs, SlowRamps, LongHold, HardStopStart, HardStopRelease };
const char* to_string(Profile p);

// Fault kinds a campaign draws (a kind fixes part and type).
enum class FaultKind {
  Bias, Drift, LoadCellStuck, NoiseBurst, Dropout, ResolverOffset, ResolverStuck,
  TorqueLoss, TotalLoss, Seized, Silence, Delay
};
const char* to_string(FaultKind k);

// When a fault starts.
enum class Onset { BeforeFirstFit, HardStop, Normal };
const char* to_string(Onset o);

struct CampaignSpec {
  std::string file;
  std::string name;
  std::uint64_t seed = 1;
  int runs = 1;
  double fault_free_share = 0.25;        // of the runs
  double duration_min_s = 16.0, duration_max_s = 24.0;
  std::string population_spec;           // absolute path of a population spec (config/population/)
  int population_members = 1;            // members 0 .. n-1 are drawn
  int population_line = 0;               // where `population` is in `file` (bbw_campaign checks the
                                         // members against the population's count there)
  double temperature_min_C = 28.0, temperature_max_C = 54.0;
  double effects_share = 0.3;            // of the corners: one plant effect switched on,
  std::vector<std::string> effects;      //   drawn from these (plant::EffectsParams' names)
  std::vector<Profile> profiles;
  // The driver's pace (optional key `pace: [min, max]`, default [1, 1]): a run's demand profile is
  // drawn as at pace 1, every step and hold of it taking 1/pace of the time (pace 2: ramps twice as
  // steep, holds half as long, ABS-like modulation at 10-20 Hz). Drawn per run only when min < max,
  // so campaigns without the key draw what they drew before it existed.
  double pace_min = 1.0, pace_max = 1.0;
  // Faults of a faulty run.
  std::vector<FaultKind> fault_kinds;
  std::vector<Onset> onsets;
  double two_faults_share = 0.3;         // of the faulty runs: two faults at once
  double same_corner_share = 0.5;        // of those: both on one corner
  double intermittent_share = 0.3;       // of the faults: a finite duration
};

// Throws bbw::config::ConfigError (file, line, key path, rule).
CampaignSpec load_campaign_spec(const std::string& file);
CampaignSpec load_campaign_spec_string(const std::string& text, const std::string& name);

}  // namespace bbw::campaign
