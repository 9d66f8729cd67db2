// bbw_monitor_replay SCENARIO.yaml CCU_CORNER.csv CORNER [--from T] [--to T] [--every N]
// Replays one corner's CCU log (the samples the CCU received, ccu_<corner>.csv of a run kept with
// --keep-logs) through a fresh CornerSupervisor configured as bbw_inproc configures the CCU's
// (config/calibrator/robust.yaml, config/faults/monitor.yaml, the scenario's plant), and prints
// per sample: the true force, the load cell, the calibrator's friction, the monitor's residual and
// its change with their thresholds, the findings. The replay matches the run up to the first
// finding (after it the run's reaction changes what the corner did; the log holds what it did).
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/common/data_path.hpp"
#include "bbw/faults/corner_supervisor.hpp"
#include "bbw/faults/monitor_yaml.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/node/ccu_core.hpp"

namespace {

constexpr const char* kUsage = "usage: bbw_monitor_replay SCENARIO.yaml CCU_CORNER.csv CORNER [--from T] [--to T] [--every N]\n";

int usage(const std::string& why) {
  std::cerr << "bbw_monitor_replay: " << why << "\n" << kUsage;
  return 2;
}

// One field of the log as a number ("nan" and "inf" included); anything else is refused.
double number(const std::string& field, const std::string& where) {
  char* end = nullptr;
  const double v = std::strtod(field.c_str(), &end);
  if (field.empty() || end != field.c_str() + field.size()) throw std::invalid_argument(where + ": '" + field + "' is no number");
  return v;
}

int run(int argc, char** argv) {
  if (argc < 4) return usage("SCENARIO.yaml, CCU_CORNER.csv and CORNER are required");
  double from = 0.0, to = 1e9;
  int every = 1;
  for (int i = 4; i < argc; i += 2) {
    const std::string a = argv[i];
    if (i + 1 >= argc) return usage(a + " needs a value");
    if (a == "--from") from = number(argv[i + 1], "--from");
    else if (a == "--to") to = number(argv[i + 1], "--to");
    else if (a == "--every") every = static_cast<int>(number(argv[i + 1], "--every"));
    else return usage("unknown argument '" + a + "'");
  }
  if (every < 1) return usage("--every must be at least 1");
  const std::string log_file = argv[2];
  auto fs = bbw::faults::load_fault_scenario(argv[1]);
  auto cal = bbw::calibration::load_config(bbw::data::path("config/calibrator/robust.yaml"));
  const auto scenario_mp =
      bbw::ccu::monitor_params_for(fs.scenario, bbw::faults::load_monitor_params(bbw::data::path("config/faults/monitor.yaml")));
  const auto target = bbw::faults::target_from_name(argv[3]);
  if (!target) return usage(std::string("CORNER must be FL, FR, RL or RR, got '") + argv[3] + "'");
  // The corner's own parameters, as the CCU builds them (its backlash, residual findings on or off).
  std::size_t corner_index = fs.scenario.corners.size();
  for (std::size_t i = 0; i < fs.scenario.corners.size(); ++i) {
    if (fs.scenario.corners[i].name == argv[3]) corner_index = i;
  }
  if (corner_index == fs.scenario.corners.size()) {
    return usage(std::string(argv[1]) + " has no corner '" + argv[3] + "'");
  }
  const auto mp = bbw::ccu::corner_monitor_params(fs.scenario, corner_index, scenario_mp);
  bbw::faults::CornerSupervisor sup(cal, mp, *target);
  std::ifstream in(log_file);
  if (!in) throw std::runtime_error(log_file + ": cannot read");
  std::string line;
  std::getline(in, line);
  // The columns by name (node/include/bbw/node/csv_log.hpp writes them).
  std::vector<std::string> header;
  {
    std::stringstream hs(line);
    std::string h;
    while (std::getline(hs, h, ',')) header.push_back(h);
  }
  auto col = [&](const std::string& name) {
    for (std::size_t k = 0; k < header.size(); ++k) {
      if (header[k] == name) return k;
    }
    throw std::invalid_argument(log_file + ":1: no column '" + name + "' (a ccu_<corner>.csv of a kept run is expected)");
  };
  const std::size_t c_t = col("time_s"), c_seq = col("seq"), c_x = col("position_rev"), c_v = col("speed_rev_per_s"),
                    c_lc = col("force_internal_kN"), c_true = col("force_true_kN"), c_T = col("temperature_C"),
                    c_i = col("motor_current_A"), c_cmd = col("command"), c_mode = col("force_mode");
  std::printf("# half_width_kN %.3f\n", mp.eol_friction_half_width_kN);
  std::printf("t x v lc true lc-true fric est curve res thr chg chgthr cal fitrms fin_lc fin_act cmd sumphi i_A tfrac hold holdthr rev revthr mod modthr\n");
  long n = 0;
  for (long line_no = 2; std::getline(in, line); ++line_no) {
    std::vector<double> c;
    std::stringstream ss(line);
    std::string f;
    const std::string where = log_file + ":" + std::to_string(line_no);
    while (std::getline(ss, f, ',')) c.push_back(number(f, where));
    if (c.size() != header.size()) {
      throw std::invalid_argument(where + ": " + std::to_string(c.size()) + " fields, the header has " + std::to_string(header.size()));
    }
    bbw::faults::CornerReading r;
    r.time_s = c[c_t];
    r.seq = static_cast<std::uint64_t>(c[c_seq]);
    r.position_rev = c[c_x];
    r.speed_rev_per_s = c[c_v];
    r.force_kN = c[c_lc];
    r.temperature_C = c[c_T];
    r.motor_current_A = c[c_i];
    r.force_command_kN = c[c_mode] != 0.0 ? c[c_cmd] : std::nan("");
    sup.on_sample(r, r.time_s);
    const auto& m = sup.monitor();
    const auto& e = sup.last_estimate();
    ++n;
    double sumphi = 0.0;
    const auto& fr = sup.calibrator().friction();
    for (std::size_t k = 0; k < fr.delta_rev.size(); ++k) sumphi += fr.delta_rev[k] * fr.stiffness_kN_per_rev[k];
    if (r.time_s < from || r.time_s > to || n % every != 0) continue;
    const double truth = c[c_true];
    std::printf("%.3f %.4f %.2f %.3f %.3f %.3f %.3f %.3f %.3f %.3f %.3f %.3f %.3f %d %.3f %s %s %.2f %.3f %.2f %.3f %.3f %.3f %.3f %.3f %.3f %.3f\n", r.time_s, r.position_rev,
                r.speed_rev_per_s, r.force_kN, truth, r.force_kN - truth, e.friction_kN, sup.view().force_estimate_kN, e.curve_force_kN,
                m.last_residual_kN(), m.last_residual_threshold_kN(), m.last_residual_change_kN(),
                m.last_residual_change_threshold_kN(), e.calibrated ? 1 : 0, sup.calibrator().stats().last_fit_rms_kN,
                bbw::faults::to_string(m.diagnosis(bbw::faults::Part::LoadCell).finding),
                bbw::faults::to_string(m.diagnosis(bbw::faults::Part::Actuator).finding), r.force_command_kN, sumphi,
                r.motor_current_A, m.torque_fraction(), m.last_hold_change_kN(), m.last_hold_threshold_kN(),
                m.last_revisit_change_kN(), m.last_revisit_threshold_kN(), m.last_modulation_kN(), m.last_modulation_threshold_kN());
  }
  return 0;
}

}  // namespace

// Exit: 0 done, 1 a file that cannot be read or a log line that is not a number row, 2 bad arguments.
int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::invalid_argument& e) {
    std::cerr << "bbw_monitor_replay: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "bbw_monitor_replay: " << e.what() << "\n";
    return 1;
  }
}
