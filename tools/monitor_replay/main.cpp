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
#include <string>
#include <vector>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/common/data_path.hpp"
#include "bbw/faults/corner_supervisor.hpp"
#include "bbw/faults/monitor_yaml.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/node/ccu_core.hpp"

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: bbw_monitor_replay SCENARIO.yaml CCU_CORNER.csv CORNER [--from T] [--to T] [--every N]\n";
    return 2;
  }
  double from = 0.0, to = 1e9;
  int every = 1;
  for (int i = 4; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--from") from = std::stod(argv[i + 1]);
    else if (a == "--to") to = std::stod(argv[i + 1]);
    else if (a == "--every") every = std::stoi(argv[i + 1]);
  }
  auto fs = bbw::faults::load_fault_scenario(argv[1]);
  auto cal = bbw::calibration::load_config(bbw::data::path("config/calibrator/robust.yaml"));
  auto mp = bbw::ccu::monitor_params_for(fs.scenario, bbw::faults::load_monitor_params(bbw::data::path("config/faults/monitor.yaml")));
  const auto target = bbw::faults::target_from_name(argv[3]);
  if (!target) return 2;
  bbw::faults::CornerSupervisor sup(cal, mp, *target);
  std::ifstream in(argv[2]);
  std::string line;
  std::getline(in, line);
  std::printf("# half_width_kN %.3f\n", mp.eol_friction_half_width_kN);
  std::printf("t x v lc true lc-true fric est curve res thr chg chgthr cal fitrms fin_lc fin_act cmd sumphi\n");
  long n = 0;
  while (std::getline(in, line)) {
    std::vector<double> c;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) c.push_back(std::strtod(f.c_str(), nullptr));
    bbw::faults::CornerReading r;
    r.time_s = c[0];
    r.seq = static_cast<std::uint64_t>(c[1]);
    r.position_rev = c[3];
    r.speed_rev_per_s = c[4];
    r.force_kN = c[5];
    r.temperature_C = c[8];
    r.motor_current_A = c[9];
    r.force_command_kN = c[11] != 0.0 ? c[10] : std::nan("");
    sup.on_sample(r, r.time_s);
    const auto& m = sup.monitor();
    const auto& e = sup.last_estimate();
    ++n;
    double sumphi = 0.0;
    const auto& fr = sup.calibrator().friction();
    for (std::size_t k = 0; k < fr.delta_rev.size(); ++k) sumphi += fr.delta_rev[k] * fr.stiffness_kN_per_rev[k];
    if (r.time_s < from || r.time_s > to || n % every != 0) continue;
    std::printf("%.3f %.4f %.2f %.3f %.3f %.3f %.3f %.3f %.3f %.3f %.3f %.3f %.3f %d %.3f %s %s %.2f %.3f\n", r.time_s, r.position_rev,
                r.speed_rev_per_s, r.force_kN, c[7], r.force_kN - c[7], e.friction_kN, sup.view().force_estimate_kN, e.curve_force_kN,
                m.last_residual_kN(), m.last_residual_threshold_kN(), m.last_residual_change_kN(),
                m.last_residual_change_threshold_kN(), e.calibrated ? 1 : 0, sup.calibrator().stats().last_fit_rms_kN,
                bbw::faults::to_string(m.diagnosis(bbw::faults::Part::LoadCell).finding),
                bbw::faults::to_string(m.diagnosis(bbw::faults::Part::Actuator).finding), r.force_command_kN, sumphi);
  }
  return 0;
}
