// bbw_population: draws the calipers of a population spec and records each one at each of the
// spec's temperatures with its rig drive (plant + local controller, no DDS), one CSV per
// caliper x temperature in the columns ./bbw calibrate reads, plus manifest.json with every
// drawn parameter. Progress and ETA on stderr.
//   ./bbw population config/population/scoring.yaml --out DIR [--members FIRST:COUNT]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "bbw/common/csv.hpp"
#include "bbw/common/json.hpp"
#include "bbw/plant/key_friction.hpp"
#include "bbw/scenario/corner_sim.hpp"
#include "bbw/scenario/population.hpp"

namespace {

const std::vector<std::string> kColumns = {
    "time_s",       "position_rev",     "force_internal_kN", "force_external_kN", "temperature_C",
    "speed_rev_per_s",  "force_true_kN",    "friction_true_kN",  "position_true_rev"};

int usage(const char* why) {
  if (why) std::fprintf(stderr, "bbw_population: %s\n", why);
  std::fprintf(stderr,
               "usage: bbw_population SPEC.yaml --out DIR [--members FIRST:COUNT]\n"
               "  writes DIR/c<member>_T<temperature>.csv (columns: time_s, position_rev,\n"
               "  force_internal_kN, force_external_kN, temperature_C, speed_rev_per_s, force_true_kN,\n"
               "  friction_true_kN, position_true_rev) and DIR/manifest.json (drawn parameters)\n");
  return 2;
}

void write_member(bbw::json::Writer& j, const bbw::plant::Caliper& c, const std::vector<std::string>& files) {
  const auto& k = c.params.key_friction;
  const auto& cv = c.params.curve;
  const bbw::plant::KeyFriction f(k);
  j.begin_object();
  j.value("member", c.index);
  j.value("seed", std::to_string(c.seed));
  j.value("key_friction", bbw::plant::describe_key_friction(k));
  j.begin_object("key_friction_params");
  j.value("elements", k.elements);
  j.value("threshold_distribution",
          k.threshold_distribution == bbw::plant::ThresholdDistribution::LogUniform ? "log_uniform" : "log_normal");
  j.value("threshold_min_rev", k.threshold_min_rev);
  j.value("threshold_max_rev", k.threshold_max_rev);
  j.value("threshold_median_rev", k.threshold_median_rev);
  j.value("threshold_log_sigma", k.threshold_log_sigma);
  j.value("half_width_kN", k.half_width_kN);
  j.value("force_share_exponent", k.force_share_exponent);
  j.value("share_log_sigma", k.share_log_sigma);
  j.value("initial_deflection", k.initial_deflection);
  j.value("structure_seed", std::to_string(k.structure_seed));
  j.numbers("thresholds_rev", f.thresholds_rev());
  j.numbers("stiffness_kN_per_rev", f.stiffness_kN_per_rev());
  j.end_object();
  j.begin_object("clamp_curve");
  j.value("contact_rev", cv.contact_rev);
  j.value("stiffness_scale", c.stiffness_scale);
  j.value("exp_coefficient_kN", cv.exp_coefficient_kN);
  j.value("linear_kN_per_rev", cv.linear_kN_per_rev);
  j.value("contact_shift_rev_per_C", cv.contact_shift_rev_per_C);
  j.value("stiffness_change_per_C", cv.stiffness_change_per_C);
  j.end_object();
  j.value("load_cell_noise_kN", c.params.sensors.load_cell_noise_kN);
  j.begin_array("recordings");
  for (const auto& f2 : files) j.value("", f2);
  j.end_array();
  j.end_object();
}

}  // namespace

int main(int argc, char** argv) {
  std::string spec_file, out_dir;
  int first = 0, count = -1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out") {
      if (i + 1 >= argc) return usage("--out needs a directory");
      out_dir = argv[++i];
    } else if (a == "--members") {
      if (i + 1 >= argc) return usage("--members needs FIRST:COUNT");
      const std::string v = argv[++i];
      const auto colon = v.find(':');
      try {
        if (colon == std::string::npos) throw std::invalid_argument(v);
        first = std::stoi(v.substr(0, colon));
        count = std::stoi(v.substr(colon + 1));
      } catch (const std::exception&) {
        return usage("--members needs FIRST:COUNT, e.g. 0:5");
      }
    } else if (a == "-h" || a == "--help") {
      usage(nullptr);
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      return usage(("unknown option " + a).c_str());
    } else if (spec_file.empty()) {
      spec_file = a;
    } else {
      return usage(("unexpected argument " + a).c_str());
    }
  }
  if (spec_file.empty()) return usage("missing SPEC.yaml");
  if (out_dir.empty()) return usage("missing --out DIR");
  try {
    const auto spec = bbw::scenario::load_population_spec(spec_file);
    if (count < 0) count = spec.count - first;
    if (first < 0 || count < 1 || first + count > spec.count) {
      return usage(("--members outside the population's " + std::to_string(spec.count) + " members").c_str());
    }
    std::filesystem::create_directories(out_dir);
    bbw::json::Writer manifest;
    manifest.begin_object();
    manifest.value("population", spec.name);
    manifest.value("spec", spec_file);
    manifest.value("seed", std::to_string(spec.seed));
    manifest.value("count", spec.count);
    manifest.numbers("temperatures_C", spec.temperatures_C);
    manifest.begin_array("members");
    const auto steps = static_cast<long long>(std::llround(spec.duration_s / spec.plant_dt_s));
    const int total = count * static_cast<int>(spec.temperatures_C.size());
    int done = 0;
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<double> row(kColumns.size());
    for (int m = first; m < first + count; ++m) {
      const auto sc = bbw::scenario::population_scenario(spec, m);
      std::vector<std::string> files;
      for (std::size_t c = 0; c < sc.corners.size(); ++c) {
        const std::string file = "c" + std::to_string(m) + "_" + sc.corners[c].name + ".csv";
        bbw::scenario::CornerSim sim(sc, c);
        bbw::csv::Writer w(out_dir + "/" + file, kColumns);
        for (long long k = 0; k < steps; ++k) {
          const auto& s = sim.step(sc.plant_dt_s);
          row = {s.time_s,        s.position_rev,  s.force_internal_kN, s.force_external_kN,  s.temperature_C,
                 s.speed_rev_per_s,   s.force_true_kN, s.friction_true_kN,  s.position_true_rev};
          w.row(row);
        }
        w.close();
        files.push_back(file);
        ++done;
        const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::fprintf(stderr, "\rbbw_population: %d/%d recordings, %.0f s elapsed, ETA %.0f s   ", done, total, el,
                     el / done * (total - done));
      }
      write_member(manifest, bbw::scenario::population_member(spec, m), files);
    }
    std::fprintf(stderr, "\n");
    manifest.end_array();
    manifest.end_object();
    manifest.save(out_dir + "/manifest.json");
    std::printf("bbw_population: %s: %d calipers x %zu temperatures -> %s (manifest.json)\n", spec.name.c_str(), count,
                spec.temperatures_C.size(), out_dir.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bbw_population: %s\n", e.what());
    return 1;
  }
  return 0;
}
