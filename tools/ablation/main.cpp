// bbw_ablation: what each robust-mode choice buys. Records every corner of the given rig
// scenarios with the plant, runs the calibrator with each choice switched off in turn, and
// prints a markdown table (worst max |error| and mean RMS over the corners, per scenario).
//   ./bbw ablation [--config config/calibrator/robust.yaml] SCENARIO.yaml [SCENARIO.yaml ...]
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "bbw/common/data_path.hpp"
#include "bbw/calibration/config_yaml.hpp"
#include "bbw/calibration/offline.hpp"
#include "bbw/calibration/rig_recording.hpp"
#include "bbw/scenario/load.hpp"

using namespace bbw::calibration;

namespace {

struct Variant {
  std::string name;
  std::function<void(CalibratorConfig&)> change;
};

std::vector<Recording> record_all(const bbw::scenario::Scenario& sc) {
  std::vector<Recording> out;
  for (std::size_t i = 0; i < sc.corners.size(); ++i) out.push_back(record_corner(sc, i));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string config_file;  // default: config/calibrator/robust.yaml of bbw's data
  std::vector<std::string> scenarios;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--config" && i + 1 < argc) config_file = argv[++i];
    else if (a == "-h" || a == "--help") {
      std::cout << "usage: bbw_ablation [--config FILE.yaml] SCENARIO.yaml [...]\n";
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      std::cerr << "bbw_ablation: unknown argument '" << a << "'\n";
      return 2;
    } else scenarios.push_back(a);
  }
  if (scenarios.empty()) {
    std::cerr << "bbw_ablation: give at least one rig scenario\n";
    return 2;
  }
  try {
    if (config_file.empty()) config_file = bbw::data::path("config/calibrator/robust.yaml");
    const auto base = load_config(config_file);
    const std::vector<Variant> variants = {
        {"robust (all choices on)", [](CalibratorConfig&) {}},
        {"x not scaled to [-1, 1]", [](CalibratorConfig& c) { c.scale_x = false; }},
        {"K_i unconstrained (no NNLS)", [](CalibratorConfig& c) { c.nonnegative_k = false; }},
        {"every K_i and the curve updated from any span", [](CalibratorConfig& c) { c.identify_per_element = false; c.min_cycle_span_rev = 0.0; }},
        {"even thresholds", [](CalibratorConfig& c) { c.spacing = ThresholdSpacing::Even; }},
        {"replay over stored samples (no streaming states)", [](CalibratorConfig& c) { c.streaming_states = false; }},
        {"K_i replaced each cycle (no smoothing)", [](CalibratorConfig& c) { c.k_smoothing = 1.0; }},
        {"paper's start rule eq. 6 (no hysteresis)", [](CalibratorConfig& c) { c.start_margin_rev = 0.0; }},
        {"no ridge", [](CalibratorConfig& c) { c.ridge = 0.0; }},
        {"drop rule j+1", [](CalibratorConfig& c) { c.drop_rule = DropRule::DropJPlus1; }},
        {"paper mode (the published method)", [](CalibratorConfig& c) { c.mode = Mode::Paper; }},
        {"paper mode, drop rule j+1", [](CalibratorConfig& c) { c.mode = Mode::Paper; c.drop_rule = DropRule::DropJPlus1; }},
    };
    std::vector<std::vector<Recording>> recs;
    std::vector<std::string> names;
    for (const auto& f : scenarios) {
      const auto sc = bbw::scenario::load_scenario(f);
      recs.push_back(record_all(sc));
      names.push_back(sc.name + " (" + std::to_string(sc.corners.size()) + " runs)");
    }
    std::printf("| variant |");
    for (const auto& n : names) std::printf(" %s: worst max kN | mean RMS kN | fits rejected |", n.c_str());
    std::printf("\n|---|");
    for (std::size_t i = 0; i < names.size(); ++i) std::printf("---|---|---|");
    std::printf("\n");
    for (const auto& v : variants) {
      CalibratorConfig c = base;
      v.change(c);
      std::printf("| %s |", v.name.c_str());
      for (const auto& set : recs) {
        double worst = 0.0, rms = 0.0;
        unsigned long long rejected = 0;
        for (const auto& r : set) {
          const auto res = run_recording(c, r);
          worst = std::max(worst, res.score.max_abs_error_kN);
          rms += res.score.rms_error_kN / static_cast<double>(set.size());
          rejected += res.stats.fits_rejected;
        }
        std::printf(" %.3f | %.3f | %llu |", worst, rms, rejected);
      }
      std::printf("\n");
      std::fflush(stdout);
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bbw_ablation: " << e.what() << "\n";
    return 1;
  }
}
