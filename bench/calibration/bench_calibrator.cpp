// Calibrator speed and memory at the paper's size (M = 8, L = 64, N = 20) and as shipped.
//   ./bbw bench Calibrator      (or build/bin/bench_calibrator)
// The recording is the paper rig at 44 C from the plant (config/scenarios/paper_rig_44C.yaml).
#include <benchmark/benchmark.h>

#include <cmath>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/calibration/offline.hpp"
#include "bbw/calibration/rig_recording.hpp"
#include "bbw/scenario/load.hpp"

using namespace bbw::calibration;

namespace {

const Recording& recording() {
  static const Recording rec = record_corner(
      bbw::scenario::load_scenario(std::string(BBW_SOURCE_DIR) + "/config/scenarios/paper_rig_44C.yaml"), 0);
  return rec;
}

// Arg 0: robust, 1: paper, 2: robust with the optional 5 ms force-delay term, 3: robust with the
// optional viscous term (speed from the position slope: the recording has no speed channel),
// 4: robust with a 0.05 rev backlash term, 5: robust with the load-dependent friction term.
// Variants 0-5 run at the paper's size (M = 8, L = 64: the robust row before issue 13);
// 6: config/calibrator/robust.yaml exactly as shipped (its own M and L); 7: the same without the
// friction memory (issue 13's last change). Variants 0-5 keep the memory off: the rows before it.
CalibratorConfig config(int variant) {
  if (variant == 6 || variant == 7) {
    auto c = load_config(std::string(BBW_SOURCE_DIR) + "/config/calibrator/robust.yaml");
    if (variant == 7) c.friction_memory = 0.0;
    return c;
  }
  auto c = load_config(std::string(BBW_SOURCE_DIR) + "/config/calibrator/robust.yaml");
  c.friction_memory = 0.0;
  c.mode = variant == 1 ? Mode::Paper : Mode::Robust;
  if (variant == 2) c.force_delay_s = 0.005;
  if (variant == 3) c.viscous_friction = true;
  if (variant == 4) c.backlash_width_rev = 0.05;
  if (variant == 5) {
    c.load_friction_gain = 0.9;
    c.load_friction_reference_kN = 36.0;
  }
  c.elements_M = 8;
  c.samples_L = 64;
  c.pf_points_N = 20;
  return c;
}

const char* variant_label(int variant, const Calibrator& cal) {
  switch (variant) {
    case 2: return "robust+force_delay";
    case 3: return "robust+viscous";
    case 4: return "robust+backlash";
    case 5: return "robust+load_friction";
    case 6: return "robust as shipped";
    case 7: return "robust as shipped, memory off";
    default: return to_string(cal.config().mode);
  }
}

// Per-sample cost including the amortised cycle-end fits: one iteration = one sample; the
// recording is replayed in a loop (time shifted so it keeps increasing).
void BM_CalibratorUpdate(benchmark::State& state) {
  const auto& rec = recording();
  const int variant = static_cast<int>(state.range(0));
  Calibrator cal(config(variant));
  std::size_t k = 0;
  double t_offset = 0.0;
  const double span = rec.time_s.back() + 0.001;
  for (auto _ : state) {
    auto e = cal.update({rec.time_s[k] + t_offset, rec.position_rev[k], rec.force_kN[k]});
    benchmark::DoNotOptimize(e);
    if (++k == rec.time_s.size()) {
      k = 0;
      t_offset += span;
    }
  }
  state.counters["fits"] = static_cast<double>(cal.stats().fits_accepted + cal.stats().fits_rejected);
  state.counters["state_bytes"] = static_cast<double>(cal.state_bytes());
  state.SetLabel(variant_label(variant, cal));
}
BENCHMARK(BM_CalibratorUpdate)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Arg(4)->Arg(5)->Arg(6)->Arg(7);

// Cost of the one update() that ends a cycle (the fit, PF update and global refit): the
// samples of each cycle are fed with the timer paused, the cycle-ending sample is timed.
void BM_CycleEndFit(benchmark::State& state) {
  const auto& rec = recording();
  const int variant = static_cast<int>(state.range(0));
  Calibrator cal(config(variant));
  // Find the indices where cycles start in this recording (same for every replay).
  std::vector<std::size_t> starts;
  {
    Calibrator probe(config(variant));
    for (std::size_t k = 0; k < rec.time_s.size(); ++k) {
      if (probe.update({rec.time_s[k], rec.position_rev[k], rec.force_kN[k]}).cycle_start) starts.push_back(k);
    }
  }
  std::size_t k = 0, next = 1;
  double t_offset = 0.0;
  const double span = rec.time_s.back() + 0.001;
  std::uint64_t fits_before = 0;
  for (auto _ : state) {
    state.PauseTiming();
    if (next >= starts.size()) {  // replay from the beginning with a fresh calibrator state
      cal = Calibrator(config(variant));
      k = 0;
      next = 1;
      t_offset += span;
    }
    for (; k < starts[next]; ++k) cal.update({rec.time_s[k] + t_offset, rec.position_rev[k], rec.force_kN[k]});
    fits_before = cal.stats().fits_accepted + cal.stats().fits_rejected;
    state.ResumeTiming();
    auto e = cal.update({rec.time_s[k] + t_offset, rec.position_rev[k], rec.force_kN[k]});
    benchmark::DoNotOptimize(e);
    ++k;
    ++next;
  }
  state.counters["fit_ran"] = static_cast<double>(cal.stats().fits_accepted + cal.stats().fits_rejected - fits_before);
  state.SetLabel(variant_label(variant, cal));
}
BENCHMARK(BM_CycleEndFit)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Arg(4)->Arg(5)->Arg(6)->Arg(7)->Unit(benchmark::kMicrosecond);

}  // namespace
