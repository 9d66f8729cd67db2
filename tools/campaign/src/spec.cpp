#include "spec.hpp"

#include <algorithm>
#include <filesystem>
#include <string_view>

#include "bbw/common/strict_yaml.hpp"

namespace bbw::campaign {

namespace {

constexpr Profile kProfiles[] = {Profile::City, Profile::Abs, Profile::SlowRamps, Profile::LongHold,
                                 Profile::HardStopStart, Profile::HardStopRelease};
constexpr FaultKind kKinds[] = {FaultKind::Bias,          FaultKind::Drift,      FaultKind::LoadCellStuck,
                                FaultKind::NoiseBurst,    FaultKind::Dropout,    FaultKind::ResolverOffset,
                                FaultKind::ResolverStuck, FaultKind::TorqueLoss, FaultKind::TotalLoss,
                                FaultKind::Seized,        FaultKind::Silence,    FaultKind::Delay};
constexpr Onset kOnsets[] = {Onset::BeforeFirstFit, Onset::HardStop, Onset::Normal};
// The plant's optional effects (plant::EffectsParams), as a scenario's corner names them.
constexpr std::string_view kEffects[] = {"viscous_friction", "sensor_delay",  "backlash",
                                         "load_dependent_friction", "creep", "thermal_drift"};

template <class E, std::size_t N>
std::vector<E> names_list(config::Reader& r, const std::string& key, const E (&all)[N]) {
  const std::vector<std::string> names = r.strings(key);
  std::vector<E> out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    bool found = false;
    for (E e : all) {
      if (names[i] != to_string(e)) continue;
      for (E seen : out) {
        if (seen == e) r.fail(key, "'" + names[i] + "' is listed twice");
      }
      out.push_back(e);
      found = true;
    }
    if (!found) {
      std::string list;
      for (E e : all) list += (list.empty() ? "" : ", ") + std::string(to_string(e));
      r.fail(key, "entry " + std::to_string(i) + " '" + names[i] + "' must be one of " + list);
    }
  }
  return out;
}

std::pair<double, double> interval(config::Reader& r, const std::string& key, const config::Range& range) {
  const std::vector<double> v = r.numbers(key, range);
  if (v.size() != 2) r.fail(key, "must be [min, max]");
  if (v[0] > v[1]) r.fail(key, "min must be <= max");
  return {v[0], v[1]};
}

CampaignSpec read(config::Reader& r) {
  CampaignSpec s;
  s.file = r.file();
  s.name = r.string("name");
  s.seed = static_cast<std::uint64_t>(r.integer("seed", 0, std::int64_t{1} << 53));
  s.runs = static_cast<int>(r.integer("runs", 1, 1000000));
  s.fault_free_share = r.number("fault_free_share", config::Range::closed(0.0, 1.0));
  std::tie(s.duration_min_s, s.duration_max_s) = interval(r, "duration_s", config::Range::closed(8.0, 600.0));
  {
    config::Reader p = r.map("population");
    s.population_spec = std::filesystem::absolute(config::resolve_relative(r.file(), p.string("spec"))).lexically_normal().string();
    s.population_members = static_cast<int>(p.integer("members", 1, 100000));
    s.population_line = p.line();
    p.finish();
  }
  std::tie(s.temperature_min_C, s.temperature_max_C) = interval(r, "temperatures_C", config::Range::closed(-40.0, 140.0));
  s.effects_share = r.number("effects_share", config::Range::closed(0.0, 1.0));
  s.effects = r.strings("effects");
  if (s.effects.empty()) r.fail("effects", "must list at least one plant effect");
  for (std::size_t i = 0; i < s.effects.size(); ++i) {
    if (std::find(std::begin(kEffects), std::end(kEffects), s.effects[i]) == std::end(kEffects)) {
      std::string list;
      for (std::string_view e : kEffects) list += (list.empty() ? "" : ", ") + std::string(e);
      r.fail("effects", "entry " + std::to_string(i) + " '" + s.effects[i] + "' must be one of " + list);
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (s.effects[j] == s.effects[i]) r.fail("effects", "'" + s.effects[i] + "' is listed twice");
    }
  }
  s.profiles = names_list(r, "profiles", kProfiles);
  if (r.has("pace")) std::tie(s.pace_min, s.pace_max) = interval(r, "pace", config::Range::closed(0.25, 4.0));
  {
    config::Reader f = r.map("faults");
    s.fault_kinds = names_list(f, "kinds", kKinds);
    s.onsets = names_list(f, "onsets", kOnsets);
    s.two_faults_share = f.number("two_faults_share", config::Range::closed(0.0, 1.0));
    s.same_corner_share = f.number("same_corner_share", config::Range::closed(0.0, 1.0));
    s.intermittent_share = f.number("intermittent_share", config::Range::closed(0.0, 1.0));
    f.finish();
  }
  r.finish();
  return s;
}

}  // namespace

const char* to_string(Profile p) {
  switch (p) {
    case Profile::City: return "city";
    case Profile::Abs: return "abs";
    case Profile::SlowRamps: return "slow_ramps";
    case Profile::LongHold: return "long_hold";
    case Profile::HardStopStart: return "hard_stop_start";
    case Profile::HardStopRelease: return "hard_stop_release";
  }
  return "?";
}

const char* to_string(FaultKind k) {
  switch (k) {
    case FaultKind::Bias: return "bias";
    case FaultKind::Drift: return "drift";
    case FaultKind::LoadCellStuck: return "load_cell_stuck";
    case FaultKind::NoiseBurst: return "noise_burst";
    case FaultKind::Dropout: return "dropout";
    case FaultKind::ResolverOffset: return "resolver_offset";
    case FaultKind::ResolverStuck: return "resolver_stuck";
    case FaultKind::TorqueLoss: return "torque_loss";
    case FaultKind::TotalLoss: return "total_loss";
    case FaultKind::Seized: return "seized";
    case FaultKind::Silence: return "silence";
    case FaultKind::Delay: return "delay";
  }
  return "?";
}

const char* to_string(Onset o) {
  switch (o) {
    case Onset::BeforeFirstFit: return "before_first_fit";
    case Onset::HardStop: return "hard_stop";
    case Onset::Normal: return "normal";
  }
  return "?";
}

CampaignSpec load_campaign_spec(const std::string& file) {
  config::Reader r = config::Reader::from_file(file);
  return read(r);
}

CampaignSpec load_campaign_spec_string(const std::string& text, const std::string& name) {
  config::Reader r = config::Reader::from_string(text, name);
  return read(r);
}

}  // namespace bbw::campaign
