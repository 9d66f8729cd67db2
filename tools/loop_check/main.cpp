// bbw_loop_check SCENARIO.yaml [--population SPEC.yaml [--members A-B]] [--calibrator FILE]
//                [--monitor FILE] [--threshold-kN X]
// Does each caliper's local force loop hold a steady clamp force? For each member of the
// population (or the scenario's own plant), runs the fault-free SCENARIO through the node cores
// over the in-memory transport and prints, per corner, the oscillation in holds (RMS of the
// high-passed true clamp force and motor current, the force's peak-to-peak, the largest
// load-cell step) and the findings raised (all false: the scenario is fault-free). Issue 14,
// docs/faults.md ("The local loop on the population").
//
// Exit: 0 no corner above --threshold-kN (default 0.1 kN high-passed RMS) and no finding,
// 3 otherwise, 1 runtime error, 2 bad arguments or config.
#include <cstdio>
#include <exception>
#include <iostream>
#include <map>
#include <optional>
#include <string>

#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/scenario/population.hpp"
#include "bbw/loop_check/loop_check.hpp"
#include "bbw/tool_cli/tool_cli.hpp"

namespace {

constexpr const char* kUsage =
    "usage: bbw_loop_check SCENARIO.yaml [--population SPEC.yaml [--members A-B]] [--calibrator FILE] "
    "[--monitor FILE] [--threshold-kN X]\n";

int usage(const std::string& why) { return bbw::tool_cli::usage_error("bbw_loop_check", kUsage, why); }

}  // namespace

int main(int argc, char** argv) {
  bbw::tool_cli::ModelArgs args;
  std::string population_file;
  int first = 0, last = -1;
  double threshold_kN = 0.1;
  const auto stop = bbw::tool_cli::parse(argc, argv, "bbw_loop_check", kUsage, args, [&](const std::string& a, const auto& value) {
    if (a == "--population") population_file = value();
    else if (a == "--members") {
      const std::string v = value();
      const auto dash = v.find('-');
      first = std::stoi(v.substr(0, dash));
      last = dash == std::string::npos ? first : std::stoi(v.substr(dash + 1));
      if (first < 0 || last < first) throw std::invalid_argument("--members must be A or A-B with 0 <= A <= B");
    } else if (a == "--threshold-kN") threshold_kN = std::stod(value());
    else return false;
    return true;
  });
  if (stop) return *stop;
  const std::string& scenario_file = args.scenario;
  try {
    auto fs = bbw::faults::load_fault_scenario(scenario_file);
    if (!fs.faults.faults.empty()) throw std::invalid_argument(scenario_file + ": must be fault-free (faults: [])");
    const auto calibrator = bbw::tool_cli::load_calibrator(args);
    const auto monitor = bbw::tool_cli::load_monitor(args);
    std::optional<bbw::scenario::PopulationSpec> pop;
    if (!population_file.empty()) {
      pop = bbw::scenario::load_population_spec(population_file);
      if (last < 0) last = pop->count - 1;
      if (last >= pop->count) return usage("--members beyond the population's " + std::to_string(pop->count));
    } else {
      first = last = -1;
    }
    std::map<std::string, int> by_finding;
    int oscillating = 0, corners = 0;
    double worst = 0.0;
    std::printf("%6s %6s %7s %10s %9s %10s %10s %10s  %s\n", "member", "corner", "hold_s", "f_hp_kN", "f_pp_kN", "i_hp_A",
                "lc_step_kN", "err_rms_kN", "findings");
    for (int m = first; m <= last; ++m) {
      bbw::scenario::Scenario s = fs.scenario;
      if (pop) s.plant = bbw::scenario::population_member(*pop, m).params;
      const auto r = bbw::loop_check::measure(s, calibrator, monitor);
      for (const auto& c : r.corners) {
        std::string f;
        for (const auto& x : c.findings) {
          f += (f.empty() ? "" : "; ") + x;
          ++by_finding[x.substr(0, x.find(' '))];
        }
        std::printf("%6d %6s %7.2f %10.4f %9.3f %10.3f %10.3f %10.3f  %s\n", m, c.corner.c_str(), c.hold_s, c.force_hp_rms_kN,
                    c.force_pp_kN, c.current_hp_rms_A, c.load_cell_step_kN, c.hold_error_rms_kN, f.c_str());
        ++corners;
        oscillating += c.force_hp_rms_kN > threshold_kN ? 1 : 0;
        worst = std::max(worst, c.force_hp_rms_kN);
      }
      std::fflush(stdout);
    }
    int findings = 0;
    std::printf("corners: %d, above %.3g kN high-passed RMS: %d, worst %.4f kN; findings:", corners, threshold_kN, oscillating,
                worst);
    for (const auto& [k, n] : by_finding) std::printf(" %s %d", k.c_str(), n), findings += n;
    std::printf(" (%d)\n", findings);
    return oscillating == 0 && findings == 0 ? 0 : 3;
  } catch (const std::invalid_argument& e) {
    std::cerr << "bbw_loop_check: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "bbw_loop_check: " << e.what() << "\n";
    return 1;
  }
}
