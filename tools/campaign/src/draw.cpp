#include "draw.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace bbw::campaign {

namespace {

// SplitMix64: the seed of run i from the campaign seed (as the population draws its members).
std::uint64_t splitmix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// A small generator whose numbers do not depend on the standard library's distributions.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() { return state_ = splitmix(state_); }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int integer(int lo, int hi) { return lo + static_cast<int>(next() % static_cast<std::uint64_t>(hi - lo + 1)); }
  bool chance(double p) { return uniform() < p; }
  template <class T>
  const T& pick(const std::vector<T>& v) { return v[static_cast<std::size_t>(integer(0, static_cast<int>(v.size()) - 1))]; }

 private:
  std::uint64_t state_;
};

struct Demand {
  std::vector<std::pair<double, double>> points{{0.0, 0.0}};
  std::vector<std::pair<double, double>> hard_stops;
  double pace = 1.0;  // every step takes dt_s / pace
  double t() const { return points.back().first; }
  double d() const { return points.back().second; }
  void to(double dt_s, double demand) { points.emplace_back(t() + dt_s / pace, demand); }
  void hold(double dt_s) { to(dt_s, d()); }
};

// City driving: moves to a new demand every 0.3-1.5 s, sometimes holding it.
void city(Demand& m, Rng& rng, double until_s) {
  while (m.t() < until_s) {
    m.to(rng.uniform(0.3, 1.5), rng.uniform(0.05, 0.55));
    if (rng.chance(0.3)) m.hold(rng.uniform(0.5, 2.5));
  }
}

// A hard stop: to 0.8-0.95 in 0.15 s, held, then released to near 0 in 0.1-0.2 s.
void hard_stop(Demand& m, Rng& rng, double hold_min_s, double hold_max_s) {
  m.to(0.15, rng.uniform(0.8, 0.95));
  const double start = m.t();
  m.hold(rng.uniform(hold_min_s, hold_max_s));
  m.hard_stops.emplace_back(start, m.t());
  m.to(rng.uniform(0.1, 0.2), rng.uniform(0.0, 0.05));
}

Demand build_profile(Profile p, Rng& rng, double duration_s, double pace) {
  Demand m;
  m.pace = pace;
  const double end = duration_s - 0.5;
  switch (p) {
    case Profile::City: city(m, rng, end); break;
    case Profile::Abs:
      city(m, rng, 3.0);
      while (m.t() < end - 3.0) {
        // ABS-like: 5-10 Hz modulation around a base demand for 1.5-4 s, then city driving.
        const double f_Hz = rng.uniform(5.0, 10.0), base = rng.uniform(0.3, 0.6), amp = rng.uniform(0.08, 0.2);
        m.to(0.2, base);
        const int half_cycles = static_cast<int>(2.0 * f_Hz * rng.uniform(1.5, 4.0));
        for (int i = 0; i < half_cycles; ++i) m.to(0.5 / f_Hz, base + (i % 2 == 0 ? amp : -amp));
        city(m, rng, std::min(end, m.t() + rng.uniform(1.0, 3.0)));
      }
      break;
    case Profile::SlowRamps:
      while (m.t() < end) {
        m.to(rng.uniform(3.0, 8.0), rng.uniform(0.4, 0.7));
        m.to(rng.uniform(3.0, 8.0), rng.uniform(0.02, 0.15));
      }
      break;
    case Profile::LongHold:
      city(m, rng, 4.0);
      while (m.t() < end) {
        m.to(0.5, rng.uniform(0.3, 0.6));
        m.hold(rng.uniform(5.0, 10.0));
        m.to(0.5, 0.05);
        city(m, rng, std::min(end, m.t() + 2.0));
      }
      break;
    case Profile::HardStopStart:
      m.hold(rng.uniform(0.1, 0.4));
      hard_stop(m, rng, 1.5, 3.0);
      city(m, rng, end);
      break;
    case Profile::HardStopRelease:
      city(m, rng, 4.0);
      while (m.t() < end - 4.0) {
        hard_stop(m, rng, 2.0, 4.0);
        city(m, rng, std::min(end, m.t() + rng.uniform(2.0, 4.0)));
      }
      city(m, rng, end);
      break;
  }
  // Cut at the run's end (interpolating the last point) and end released. The scenario gives
  // times to 0.1 ms (scenario_yaml): a point within 0.1 ms before the cut stands for it, or both
  // would be written as one time (seed 2903, run 12: a point 0.04 ms before it).
  constexpr double kMinStep_s = 1e-4;
  std::vector<std::pair<double, double>> cut;
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    if (m.points[i].first <= end) {
      cut.push_back(m.points[i]);
      continue;
    }
    const auto& a = m.points[i - 1];
    const auto& b = m.points[i];
    if (end - a.first >= kMinStep_s) cut.emplace_back(end, a.second + (b.second - a.second) * (end - a.first) / (b.first - a.first));
    break;
  }
  cut.emplace_back(duration_s - 0.2, 0.0);
  cut.emplace_back(duration_s, 0.0);
  m.points = std::move(cut);
  m.hard_stops.erase(std::remove_if(m.hard_stops.begin(), m.hard_stops.end(),
                                    [&](const auto& h) { return h.second > end - 0.5; }),
                     m.hard_stops.end());
  return m;
}

Profile profile_for(const CampaignSpec& spec, Onset onset, Rng& rng) {
  if (onset != Onset::HardStop) return rng.pick(spec.profiles);
  std::vector<Profile> with_stops;
  for (Profile p : spec.profiles) {
    if (p == Profile::HardStopStart || p == Profile::HardStopRelease) with_stops.push_back(p);
  }
  if (with_stops.empty()) with_stops = {Profile::HardStopRelease};
  return rng.pick(with_stops);
}

faults::Part part_of_kind(FaultKind k) {
  switch (k) {
    case FaultKind::Bias:
    case FaultKind::Drift:
    case FaultKind::LoadCellStuck:
    case FaultKind::NoiseBurst:
    case FaultKind::Dropout: return faults::Part::LoadCell;
    case FaultKind::ResolverOffset:
    case FaultKind::ResolverStuck: return faults::Part::Resolver;
    case FaultKind::TorqueLoss:
    case FaultKind::TotalLoss:
    case FaultKind::Seized: return faults::Part::Actuator;
    case FaultKind::Silence:
    case FaultKind::Delay: return faults::Part::Network;
  }
  return faults::Part::LoadCell;
}

faults::FaultType type_of_kind(FaultKind k) {
  switch (k) {
    case FaultKind::Bias: return faults::FaultType::Bias;
    case FaultKind::Drift: return faults::FaultType::Drift;
    case FaultKind::LoadCellStuck:
    case FaultKind::ResolverStuck: return faults::FaultType::Stuck;
    case FaultKind::NoiseBurst: return faults::FaultType::NoiseBurst;
    case FaultKind::Dropout: return faults::FaultType::Dropout;
    case FaultKind::ResolverOffset: return faults::FaultType::Offset;
    case FaultKind::TorqueLoss: return faults::FaultType::TorqueLoss;
    case FaultKind::TotalLoss: return faults::FaultType::TotalLoss;
    case FaultKind::Seized: return faults::FaultType::Seized;
    case FaultKind::Silence: return faults::FaultType::Silence;
    case FaultKind::Delay: return faults::FaultType::Delay;
  }
  return faults::FaultType::Bias;
}

double onset_time(Onset o, const Demand& m, double duration_s, Rng& rng) {
  switch (o) {
    case Onset::BeforeFirstFit: return rng.uniform(0.3, 1.5);
    case Onset::HardStop:
      if (!m.hard_stops.empty()) {
        const auto& h = m.hard_stops[static_cast<std::size_t>(rng.integer(0, static_cast<int>(m.hard_stops.size()) - 1))];
        if (h.second - h.first > 0.6) return rng.uniform(h.first + 0.2, h.second - 0.3);
      }
      break;
    case Onset::Normal: break;
  }
  return rng.uniform(3.0, duration_s - 4.0);
}

PlannedFault draw_fault(const CampaignSpec& spec, FaultKind kind, Onset onset, faults::Target corner, double at_s,
                        double duration_s, Rng& rng) {
  PlannedFault p;
  p.kind = kind;
  p.onset = onset;
  faults::FaultSpec& f = p.spec;
  f.at_s = std::round(at_s * 1000.0) / 1000.0;
  f.target = corner;
  f.part = part_of_kind(kind);
  f.type = type_of_kind(kind);
  const double lo = detectability_limit(kind), hi = kind_max_magnitude(kind);
  const double sign = rng.chance(0.5) ? 1.0 : -1.0;
  auto magnitude = [&] { return std::round(rng.uniform(lo, hi) * 1000.0) / 1000.0; };
  switch (kind) {
    case FaultKind::Bias: f.bias_kN = sign * magnitude(); break;
    case FaultKind::Drift: f.rate_kN_per_s = sign * magnitude(); break;
    case FaultKind::NoiseBurst: f.rms_kN = magnitude(); break;
    case FaultKind::ResolverOffset: f.offset_rev = sign * magnitude(); break;
    case FaultKind::TorqueLoss: f.torque_loss_percent = std::round(rng.uniform(lo, hi)); break;
    case FaultKind::Delay: f.delay_ms = std::round(rng.uniform(lo, hi)); break;
    default: break;
  }
  const double room_s = duration_s - 1.0 - f.at_s;
  if (kind == FaultKind::Silence) {
    f.duration_s = std::round(std::min(room_s, rng.uniform(0.1, 1.0)) * 1000.0) / 1000.0;
  } else if (rng.chance(spec.intermittent_share) && room_s > 0.4) {
    f.duration_s = std::round(std::min(room_s, rng.uniform(0.3, 2.0)) * 1000.0) / 1000.0;
  }
  return p;
}

}  // namespace

double detectability_limit(FaultKind kind) {
  switch (kind) {
    case FaultKind::Bias: return 1.0;          // kN
    case FaultKind::Drift: return 0.2;         // kN/s (slowest rate drawn: reaches the bias limit in 5 s)
    case FaultKind::NoiseBurst: return 0.25;   // kN RMS
    case FaultKind::ResolverOffset: return 0.02;  // rev
    case FaultKind::TorqueLoss: return 50.0;   // %
    case FaultKind::Delay: return 20.0;        // ms
    default: return 0.0;
  }
}

bool above_limit(const std::string& kind, double magnitude, double at_s, double end_s) {
  for (FaultKind k : {FaultKind::Bias, FaultKind::Drift, FaultKind::NoiseBurst, FaultKind::ResolverOffset,
                      FaultKind::TorqueLoss, FaultKind::Delay}) {
    if (kind != to_string(k)) continue;
    if (std::abs(magnitude) < detectability_limit(k) - 1e-9) return false;
    if (k == FaultKind::Drift) return std::abs(magnitude) * (end_s - at_s) >= detectability_limit(FaultKind::Bias) - 1e-9;
    return true;
  }
  return true;
}

double kind_max_magnitude(FaultKind kind) {
  switch (kind) {
    case FaultKind::Bias: return 3.0;
    case FaultKind::Drift: return 2.0;
    case FaultKind::NoiseBurst: return 0.6;
    case FaultKind::ResolverOffset: return 0.3;
    case FaultKind::TorqueLoss: return 90.0;
    case FaultKind::Delay: return 60.0;
    default: return 0.0;
  }
}

RunPlan draw_run(const CampaignSpec& spec, int index) {
  if (index < 0 || index >= spec.runs) throw std::out_of_range("run index " + std::to_string(index) + " outside the campaign");
  Rng rng(splitmix(spec.seed ^ splitmix(static_cast<std::uint64_t>(index) + 1)));
  RunPlan r;
  r.index = index;
  r.scenario_seed = rng.next() % 1000000007ull;
  // Fault-free runs spread evenly: run i is fault-free when floor((i + 1) s) > floor(i s) for the
  // share s (so any first n runs hold floor(n s) of them, whatever the run count).
  r.fault_free = std::floor((index + 1) * spec.fault_free_share + 1e-9) > std::floor(index * spec.fault_free_share + 1e-9);
  r.duration_s = std::round(rng.uniform(spec.duration_min_s, spec.duration_max_s));
  r.member = rng.integer(0, spec.population_members - 1);
  for (std::size_t c = 0; c < 4; ++c) {
    r.temperature_C[c] = std::round(rng.uniform(spec.temperature_min_C, spec.temperature_max_C) * 10.0) / 10.0;
    if (rng.chance(spec.effects_share)) {
      r.effect[c] = spec.effects[static_cast<std::size_t>(rng.integer(0, static_cast<int>(spec.effects.size()) - 1))];
    }
  }
  const Onset first_onset = rng.pick(spec.onsets);
  r.profile = r.fault_free ? rng.pick(spec.profiles) : profile_for(spec, first_onset, rng);
  r.pace = spec.pace_min < spec.pace_max ? rng.uniform(spec.pace_min, spec.pace_max) : spec.pace_min;
  const Demand m = build_profile(r.profile, rng, r.duration_s, r.pace);
  r.demand = m.points;
  r.hard_stops = m.hard_stops;
  if (r.fault_free) return r;
  const auto corner = static_cast<faults::Target>(rng.integer(0, 3));
  const FaultKind k1 = rng.pick(spec.fault_kinds);
  const double at1 = onset_time(first_onset, m, r.duration_s, rng);
  r.faults.push_back(draw_fault(spec, k1, first_onset, corner, at1, r.duration_s, rng));
  if (rng.chance(spec.two_faults_share)) {
    const bool same = rng.chance(spec.same_corner_share);
    std::vector<FaultKind> kinds;
    for (FaultKind k : spec.fault_kinds) {
      // Two faults of one part on one corner are one broken part; a second network fault on
      // the same corner hides the first.
      if (!same || (part_of_kind(k) != part_of_kind(k1) && part_of_kind(k) != faults::Part::Network)) kinds.push_back(k);
    }
    if (!kinds.empty()) {
      faults::Target c2 = corner;
      if (!same) c2 = static_cast<faults::Target>((static_cast<int>(corner) + rng.integer(1, 3)) % 4);
      // At once: within 0.3 s of the first (the same onset class).
      const double at2 = std::min(at1 + rng.uniform(0.0, 0.3), r.duration_s - 4.0);
      r.faults.push_back(draw_fault(spec, rng.pick(kinds), first_onset, c2, at2, r.duration_s, rng));
    }
  }
  return r;
}

std::string scenario_yaml(const CampaignSpec& spec, const RunPlan& r, const std::string& plant_file) {
  std::ostringstream o;
  o.precision(10);
  o << "# Drawn by bbw_campaign: campaign '" << spec.name << "' (seed " << spec.seed << "), run " << r.index << ", profile "
    << to_string(r.profile) << (r.pace != 1.0 ? ", pace " + std::to_string(r.pace) : std::string()) << (r.fault_free ? ", fault-free" : "") << ".\n";
  o << "name: " << spec.name << "_" << r.index << "\n";
  o << "seed: " << r.scenario_seed << "\n";
  o << "duration_s: " << r.duration_s << "\n";
  o << "plant_dt_s: 0.001\nccu_period_s: 0.005\n";
  o << "plant: " << plant_file << "\n";
  o << "population: {spec: " << spec.population_spec << ", member: " << r.member << "}\n";
  o << "demand:\n  max_clamp_force_kN: 40.0\n  front_share: 0.6\n  profile: [";
  for (std::size_t i = 0; i < r.demand.size(); ++i) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s[%.4f, %.4f]", i == 0 ? "" : ", ", r.demand[i].first, r.demand[i].second);
    o << buf;
  }
  o << "]\ncorners:\n";
  constexpr const char* kNames[] = {"FL", "FR", "RL", "RR"};
  for (std::size_t c = 0; c < 4; ++c) {
    o << "  - name: " << kNames[c] << "\n    temperature_C: " << r.temperature_C[c] << "\n";
    if (!r.effect[c].empty()) o << "    effects: {" << r.effect[c] << ": {}}\n";
    o << "    drive: {mode: demand, feedback: load_cell}\n";
  }
  if (!r.faults.empty()) {
    o << "faults:\n";
    for (const PlannedFault& p : r.faults) {
      const faults::FaultSpec& f = p.spec;
      o << "  - {at_s: " << f.at_s << ", corner: " << faults::to_string(f.target) << ", part: " << faults::to_string(f.part)
        << ", type: " << faults::to_string(f.type);
      switch (p.kind) {
        case FaultKind::Bias: o << ", bias_kN: " << f.bias_kN; break;
        case FaultKind::Drift: o << ", rate_kN_per_s: " << f.rate_kN_per_s; break;
        case FaultKind::NoiseBurst: o << ", rms_kN: " << f.rms_kN; break;
        case FaultKind::ResolverOffset: o << ", offset_rev: " << f.offset_rev; break;
        case FaultKind::TorqueLoss: o << ", loss_percent: " << f.torque_loss_percent; break;
        case FaultKind::Delay: o << ", delay_ms: " << f.delay_ms; break;
        default: break;
      }
      if (f.duration_s) o << ", duration_s: " << *f.duration_s;
      o << "}   # " << to_string(p.kind) << ", onset " << to_string(p.onset) << "\n";
    }
  }
  return o.str();
}

}  // namespace bbw::campaign
