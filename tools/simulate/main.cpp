// bbw_simulate SCENARIO.yaml --out DIR [--no-plot] [--allow-large]
// Runs every corner of the scenario (plant + local controller, no DDS) for duration_s at
// plant_dt_s and writes DIR/<corner>.csv and DIR/<corner>.png (load-cell and external force
// against position, a paper Fig. 5 look-alike).
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "bbw/common/csv.hpp"
#include "bbw/common/plot.hpp"
#include "bbw/scenario/corner_sim.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/scenario/run_checks.hpp"

namespace {

const std::vector<std::string> kColumns = {
    "time_s",        "position_rev",     "force_internal_kN", "force_external_kN", "temperature_C",
    "speed_rev_per_s",   "motor_current_A",  "force_true_kN",     "command",           "command_is_force",
    "current_command_A", "friction_true_kN", "position_true_rev"};

int usage(const char* why) {
  if (why) std::fprintf(stderr, "bbw_simulate: %s\n", why);
  std::fprintf(stderr,
               "usage: bbw_simulate SCENARIO.yaml --out DIR [--no-plot] [--allow-large]\n"
               "  writes DIR/<corner>.csv (columns: time_s, position_rev, force_internal_kN,\n"
               "  force_external_kN, temperature_C, ...) and DIR/<corner>.png per corner;\n"
               "  --allow-large accepts a run over the size limits (docs/security.md, \"Inputs\")\n");
  return 2;
}

void plot_corner(const std::string& dir, const std::string& corner, const std::string& title) {
  const std::string csv = dir + "/" + corner + ".csv";
  const std::string png = dir + "/" + corner + ".png";
  std::string gp;
  gp += "set terminal pngcairo size 1000,700 noenhanced\n";
  gp += "set output " + bbw::plot::quote(png) + "\n";
  gp += "set datafile separator ','\n";
  gp += "set title " + bbw::plot::quote(title) + "\n";
  gp += "set xlabel 'actuator position (rev)'\nset ylabel 'clamp force (kN)'\nset grid\n";
  gp += "set key top left\n";
  gp += "plot " + bbw::plot::quote(csv) +
        " every 8::1 using 2:3 with lines lw 1 lc rgb '#1f77b4' title 'internal load cell', \\\n"
        "     " + bbw::plot::quote(csv) +
        " every 8::1 using 2:4 with lines lw 2 lc rgb '#d62728' title 'external sensor (true)'\n";
  bbw::plot::run_gnuplot(gp, dir + "/" + corner + ".gp");
}

}  // namespace

int main(int argc, char** argv) {
  std::string scenario_file;
  std::string out_dir;
  bool plot = true;
  bool allow_large = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out") {
      if (i + 1 >= argc) return usage("--out needs a directory");
      out_dir = argv[++i];
    } else if (a == "--no-plot") {
      plot = false;
    } else if (a == "--allow-large") {
      allow_large = true;
    } else if (a == "-h" || a == "--help") {
      usage(nullptr);
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      return usage(("unknown option " + a).c_str());
    } else if (scenario_file.empty()) {
      scenario_file = a;
    } else {
      return usage(("unexpected argument " + a).c_str());
    }
  }
  if (scenario_file.empty()) return usage("missing SCENARIO.yaml");
  if (out_dir.empty()) return usage("missing --out DIR");

  try {
    const bbw::scenario::Scenario sc = bbw::scenario::load_scenario(scenario_file);
    if (!allow_large) bbw::scenario::check_run_size(sc);
    std::filesystem::create_directories(out_dir);
    const auto steps = static_cast<long long>(std::llround(sc.duration_s / sc.plant_dt_s));
    for (std::size_t c = 0; c < sc.corners.size(); ++c) {
      bbw::scenario::CornerSim sim(sc, c);
      const std::string& name = sc.corners[c].name;
      bbw::csv::Writer w(out_dir + "/" + name + ".csv", kColumns);
      std::vector<double> row(kColumns.size());
      for (long long k = 0; k < steps; ++k) {
        const auto& s = sim.step(sc.plant_dt_s);
        row = {s.time_s,           s.position_rev,
               s.force_internal_kN, s.force_external_kN,
               s.temperature_C,    s.speed_rev_per_s,
               s.motor_current_A,  s.force_true_kN,
               s.command,          s.command_kind == bbw::scenario::CommandKind::Force ? 1.0 : 0.0,
               s.current_command_A, s.friction_true_kN,
               s.position_true_rev};
        w.row(row);
      }
      w.close();
      if (plot) {
        char title[256];
        std::snprintf(title, sizeof title, "%s: corner %s at %.1f C", sc.name.c_str(), name.c_str(),
                      sc.corners[c].conditions.temperature_C);
        plot_corner(out_dir, name, title);
      }
      std::printf("bbw_simulate: %s: %lld samples -> %s/%s.csv%s\n", name.c_str(), steps, out_dir.c_str(),
                  name.c_str(), plot ? " (+ .png)" : "");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bbw_simulate: %s\n", e.what());
    return 1;
  }
  return 0;
}
