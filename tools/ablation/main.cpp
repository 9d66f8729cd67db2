// bbw_ablation: what each robust-mode choice buys. Records every corner of the given rig
// scenarios with the plant, runs the calibrator with each choice switched off in turn, and
// prints a markdown table (worst max |error| and mean RMS over the corners, per scenario).
//   ./bbw ablation [--config config/calibrator/robust.yaml] SCENARIO.yaml [SCENARIO.yaml ...]
//                  [--population SPEC.yaml [--members FIRST:COUNT]] [--distribution]
// --population adds every member x temperature of a caliper population as one more set;
// --distribution prints, instead of the table, each set's per-recording worst case with the
// shipped config (median, p90, worst and which recording) and every recording's figures.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "bbw/common/data_path.hpp"
#include "bbw/calibration/config_yaml.hpp"
#include "bbw/calibration/offline.hpp"
#include "bbw/calibration/rig_recording.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/scenario/population.hpp"

using namespace bbw::calibration;

namespace {

struct Variant {
  std::string name;
  std::function<void(CalibratorConfig&)> change;
};

struct Set {
  std::string name;
  std::vector<std::string> labels;  // one per recording
  std::vector<Recording> recs;
};

Set record_scenario(const bbw::scenario::Scenario& sc) {
  Set out;
  out.name = sc.name + " (" + std::to_string(sc.corners.size()) + " runs)";
  for (std::size_t i = 0; i < sc.corners.size(); ++i) {
    out.labels.push_back(sc.corners[i].name);
    out.recs.push_back(record_corner(sc, i));
  }
  return out;
}

Set record_population(const std::string& file, int first, int count) {
  const auto spec = bbw::scenario::load_population_spec(file);
  if (count < 0) count = spec.count - first;
  if (first < 0 || count < 1 || first + count > spec.count) {
    throw std::invalid_argument("--members outside the population's " + std::to_string(spec.count) + " members");
  }
  Set out;
  const auto t0 = std::chrono::steady_clock::now();
  const int total = count * static_cast<int>(spec.temperatures_C.size());
  for (int m = first; m < first + count; ++m) {
    const auto sc = bbw::scenario::population_scenario(spec, m);
    for (std::size_t i = 0; i < sc.corners.size(); ++i) {
      std::string label = "c";
      label += std::to_string(m);
      label += "_";
      label += sc.corners[i].name;
      label += " (";
      label += bbw::plant::describe_key_friction(sc.plant.key_friction);
      label += ")";
      out.labels.push_back(label);
      out.recs.push_back(record_corner(sc, i));
      const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const auto done = static_cast<double>(out.recs.size());
      std::fprintf(stderr, "\rbbw_ablation: recorded %zu/%d, ETA %.0f s   ", out.recs.size(), total,
                   el / done * (total - done));
    }
  }
  std::fprintf(stderr, "\n");
  out.name = "population " + spec.name + " (" + std::to_string(count) + " calipers x " +
             std::to_string(spec.temperatures_C.size()) + " temperatures)";
  return out;
}

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size()))) - 1;
  return v[std::min(i, v.size() - 1)];
}

void print_distribution(const CalibratorConfig& c, const Set& set) {
  std::vector<double> worst, rms;
  std::size_t arg = 0;
  for (std::size_t k = 0; k < set.recs.size(); ++k) {
    const auto res = run_recording(c, set.recs[k]);
    worst.push_back(res.stats.fits_accepted > 0 ? res.score.max_abs_error_kN : INFINITY);
    rms.push_back(res.score.rms_error_kN);
    if (worst.back() > worst[arg]) arg = k;
    std::printf("%-70s worst %.3f kN  rms %.4f kN  fits %llu/%llu  first fit %.1f s  max at %.2f s\n", set.labels[k].c_str(),
                worst.back(), rms.back(), static_cast<unsigned long long>(res.stats.fits_accepted),
                static_cast<unsigned long long>(res.stats.fits_accepted + res.stats.fits_rejected),
                res.stats.first_fit_time_s, res.score.time_of_max_error_s);
    std::fflush(stdout);
  }
  std::size_t over = 0;
  for (double w : worst) over += w > 0.27 ? 1 : 0;
  std::printf("%s: worst |f_hat - f_ext| per recording: median %.3f, p90 %.3f, worst %.3f kN (%s); "
              "RMS median %.4f, worst %.4f kN; %zu of %zu over 0.27 kN\n",
              set.name.c_str(), quantile(worst, 0.5), quantile(worst, 0.9), worst[arg], set.labels[arg].c_str(),
              quantile(rms, 0.5), quantile(rms, 1.0), over, worst.size());
}

}  // namespace

int main(int argc, char** argv) {
  std::string config_file;  // default: config/calibrator/robust.yaml of bbw's data
  std::vector<std::string> scenarios, populations;
  int first = 0, count = -1;
  bool distribution = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--config" && i + 1 < argc) config_file = argv[++i];
    else if (a == "--population" && i + 1 < argc) populations.push_back(argv[++i]);
    else if (a == "--members" && i + 1 < argc) {
      const std::string v = argv[++i];
      const auto colon = v.find(':');
      if (colon == std::string::npos) {
        std::cerr << "bbw_ablation: --members needs FIRST:COUNT\n";
        return 2;
      }
      first = std::atoi(v.substr(0, colon).c_str());
      count = std::atoi(v.substr(colon + 1).c_str());
    } else if (a == "--distribution") distribution = true;
    else if (a == "-h" || a == "--help") {
      std::cout << "usage: bbw_ablation [--config FILE.yaml] [SCENARIO.yaml ...] [--population SPEC.yaml\n"
                   "                    [--members FIRST:COUNT]] [--distribution]\n";
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      std::cerr << "bbw_ablation: unknown argument '" << a << "'\n";
      return 2;
    } else scenarios.push_back(a);
  }
  if (scenarios.empty() && populations.empty()) {
    std::cerr << "bbw_ablation: give at least one rig scenario or --population\n";
    return 2;
  }
  try {
    if (config_file.empty()) config_file = bbw::data::path("config/calibrator/robust.yaml");
    const auto base = load_config(config_file);
    const std::vector<Variant> variants = {
        {"robust (all choices on)", [](CalibratorConfig&) {}},
        {"no residual averaging (residual_window 1)", [](CalibratorConfig& c) { c.residual_window = 1; }},
        {"8 elements over the same span (ratio 0.45)", [](CalibratorConfig& c) { c.elements_M = 8; c.geometric_ratio = 0.45; }},
        {"L = 64 samples per cycle", [](CalibratorConfig& c) { c.samples_L = 64; }},
        {"previous settings, current code: M = 8, L = 64, Delta_max 0.4, ratio 0.6, window 1",
         [](CalibratorConfig& c) {
           c.elements_M = 8;
           c.samples_L = 64;
           c.delta_max_rev = 0.4;
           c.geometric_ratio = 0.6;
           c.residual_window = 1;
         }},
        {"x not scaled to [-1, 1]", [](CalibratorConfig& c) { c.scale_x = false; }},
        {"K_i unconstrained (no NNLS)", [](CalibratorConfig& c) { c.nonnegative_k = false; }},
        {"every K_i and the curve updated from any span", [](CalibratorConfig& c) { c.identify_per_element = false; c.min_cycle_span_rev = 0.0; }},
        {"even thresholds", [](CalibratorConfig& c) { c.spacing = ThresholdSpacing::Even; }},
        {"replay over stored samples (no streaming states)", [](CalibratorConfig& c) { c.streaming_states = false; }},
        {"K_i replaced each cycle (no smoothing)", [](CalibratorConfig& c) { c.k_smoothing = 1.0; }},
        {"paper's start rule eq. 6 (no hysteresis)", [](CalibratorConfig& c) { c.start_margin_rev = 0.0; }},
        {"no ridge", [](CalibratorConfig& c) { c.ridge = 0.0; }},
        {"drop rule j+1", [](CalibratorConfig& c) { c.drop_rule = DropRule::DropJPlus1; }},
        {"+ friction memory 0.9 (issue 13 item 3; not shipped: docs/calibrator.md)", [](CalibratorConfig& c) { c.friction_memory = 0.9; }},
        {"paper mode (the published method)", [](CalibratorConfig& c) { c.mode = Mode::Paper; }},
        {"paper mode, drop rule j+1", [](CalibratorConfig& c) { c.mode = Mode::Paper; c.drop_rule = DropRule::DropJPlus1; }},
    };
    std::vector<Set> sets;
    for (const auto& f : scenarios) sets.push_back(record_scenario(bbw::scenario::load_scenario(f)));
    for (const auto& f : populations) sets.push_back(record_population(f, first, count));
    if (distribution) {
      for (const auto& set : sets) print_distribution(base, set);
      return 0;
    }
    std::vector<std::string> names;
    std::vector<std::vector<Recording>> recs;
    for (auto& set : sets) {
      names.push_back(set.name);
      recs.push_back(std::move(set.recs));
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
