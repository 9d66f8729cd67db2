// bbw_vehicle_inproc SCENARIO.yaml --out DIR [--calibrator FILE] [--monitor FILE]
//                    [--feedback load_cell|eol_curve|compensated] [--exchange-every N] [--no-plots]
// A vehicle scenario (config/scenarios/vehicle/) in one process, lockstep over the in-memory
// transport: the CCU (with its brake functions) and the four corners of InProcessRun, the vehicle
// and the pedal as further participants of its barrier. Writes DIR/summary.json (the `vehicle`
// object, docs/vehicle.md), DIR/vehicle.csv (one row per CCU period) and the plots (speeds, slips,
// clamp forces, mu used, x-y path) as PNGs through gnuplot.
//
// Exit: 0 done, 1 runtime error, 2 bad arguments or config.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <memory>
#include <string>
#include <vector>

#include "bbw/common/json.hpp"
#include "bbw/common/strict_yaml.hpp"
#include "bbw/node/csv_log.hpp"
#include "bbw/vehicle_run/metrics.hpp"
#include "bbw/tool_cli/tool_cli.hpp"
#include "bbw/vehicle_run/vehicle_run.hpp"

namespace {

constexpr const char* kUsage =
    "usage: bbw_vehicle_inproc SCENARIO.yaml --out DIR [--calibrator FILE] [--monitor FILE] "
    "[--feedback load_cell|eol_curve|compensated] [--exchange-every N] [--no-plots]\n";

int usage(const std::string& why) { return bbw::tool_cli::usage_error("bbw_vehicle_inproc", kUsage, why); }

void write_csv(const std::string& file, const std::vector<bbw::vehicle_run::PeriodTrace>& tr) {
  std::ofstream f(file);
  if (!f) throw std::runtime_error(file + ": cannot write");
  f << "time_s,speed_m_s,speed_estimate_m_s,x_m,y_m,yaw_rate_deg_s,ax_m_s2,path_m,steer_deg,demand,split_mu";
  const char* n[4] = {"FL", "FR", "RL", "RR"};
  for (const char* c : n) {
    f << ",wheel_speed_" << c << "_m_s,slip_" << c << ",mu_used_" << c << ",surface_mu_scale_" << c << ",command_" << c
      << "_kN,clamp_true_" << c << "_kN,clamp_estimate_" << c << "_kN,disc_" << c << "_C,abs_" << c << ",target_slip_" << c;
  }
  f << "\n" << std::setprecision(9);
  for (const auto& t : tr) {
    f << t.time_s << ',' << t.speed_m_s << ',' << t.speed_estimate_m_s << ',' << t.x_m << ',' << t.y_m << ','
      << t.yaw_rate_rad_s * 180.0 / M_PI << ',' << t.ax_m_s2 << ',' << t.path_m << ',' << t.steer_rad * 180.0 / M_PI << ','
      << t.demand << ',' << (t.split_mu ? 1 : 0);
    for (std::size_t w = 0; w < 4; ++w) {
      f << ',' << t.wheel_speed_m_s[w] << ',' << t.slip[w] << ',' << t.mu_used[w] << ',' << t.surface_mu_scale[w] << ','
        << t.command_kN[w] << ',' << t.clamp_true_kN[w] << ',' << t.clamp_estimate_kN[w] << ',' << t.disc_C[w] << ','
        << (t.abs_active[w] ? 1 : 0) << ',' << t.target_slip[w];
    }
    f << "\n";
  }
}


}  // namespace

int main(int argc, char** argv) {
  bbw::tool_cli::ModelArgs args;
  std::string out_dir, feedback;
  int exchange_every = 1;
  bool want_plots = true;
  const auto stop = bbw::tool_cli::parse(argc, argv, "bbw_vehicle_inproc", kUsage, args, [&](const std::string& a, const auto& value) {
    if (a == "--out") out_dir = value();
    else if (a == "--feedback") feedback = value();
    else if (a == "--exchange-every") exchange_every = std::stoi(value());
    else if (a == "--no-plots") want_plots = false;
    else return false;
    return true;
  });
  if (stop) return *stop;
  const std::string& scenario_file = args.scenario;
  if (out_dir.empty()) return usage("--out DIR is required");
  if (exchange_every < 1 || exchange_every > 64) return usage("--exchange-every must be in [1, 64]");
  if (!feedback.empty() && feedback != "load_cell" && feedback != "eol_curve" && feedback != "compensated") {
    return usage("--feedback must be load_cell, eol_curve or compensated, got '" + feedback + "'");
  }
  bbw::vehicle_run::VehicleScenario scenario;
  bbw::calibration::CalibratorConfig calibrator;
  bbw::vehicle_run::VehicleRunOptions options;
  try {
    scenario = bbw::vehicle_run::load_vehicle_scenario(scenario_file);
    calibrator = bbw::tool_cli::load_calibrator(args);
    options.in_process.monitor = bbw::tool_cli::load_monitor(args);
    // The calibration study (docs/vehicle.md): (a) load_cell: the raw load cell; (b) eol_curve:
    // the end-of-line curve (the calibrator's initial curve) at the measured position;
    // (c)/(d) compensated: the load cell less the friction the CCU's calibrator (--calibrator)
    // identifies.
    if (!feedback.empty()) {
      const auto f = feedback == "compensated" ? bbw::corner_unit::ForceFeedback::Compensated
                                               : bbw::corner_unit::ForceFeedback::LoadCell;
      for (auto& c : scenario.corners.scenario.corners) c.drive.feedback = f;
      options.in_process.friction_feedback = feedback == "compensated";
      if (feedback == "eol_curve") options.curve_feedback = calibrator.initial_curve;
    }
    options.exchange_every_samples = exchange_every;
    options.in_process.process_faults = true;  // a corner kill in a vehicle scenario is carried out in process
  } catch (const bbw::config::ConfigError& e) {
    std::cerr << "bbw_vehicle_inproc: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "bbw_vehicle_inproc: " << e.what() << "\n";
    return 2;
  }
  try {
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec || !std::filesystem::is_directory(out_dir)) throw std::runtime_error(out_dir + ": cannot create output directory");
    bbw::vehicle_run::VehicleRun run(scenario, calibrator, options);
    // The CCU's and the corners' logs, as bbw_inproc and the DDS processes write them.
    bbw::node::CcuCsvLog ccu_log(out_dir, run.in_process().ccu());
    run.in_process().ccu().set_observer(&ccu_log);
    std::vector<std::unique_ptr<bbw::node::CornerPeriodsLog>> corner_logs;
    for (std::size_t i = 0; i < run.in_process().corners(); ++i) {
      const std::string name = bbw::corner_name(run.in_process().corner(i).corner());
      corner_logs.push_back(std::make_unique<bbw::node::CornerPeriodsLog>(out_dir + "/corner_" + name + "_periods.csv", 0));
      run.in_process().set_corner_observer(i, corner_logs.back().get());
    }
    const auto t0 = std::chrono::steady_clock::now();
    run.run();
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    run.in_process().ccu().set_observer(nullptr);
    ccu_log.flush();
    for (auto& l : corner_logs) l->flush();
    const auto m = bbw::vehicle_run::vehicle_metrics(scenario, run);
    write_csv(out_dir + "/vehicle.csv", run.trace());
    bbw::vehicle_run::write_truth_csv(out_dir + "/vehicle_truth.csv", run.vehicle_node().truth());
    bbw::vehicle_run::write_vehicle_file(out_dir + "/vehicle.json", m);
    bbw::json::Writer w;
    w.begin_object();
    w.value("scenario", scenario.name);
    w.value("transport", "memory");
    w.value("mode", "lockstep");
    w.value("duration_s", scenario.corners.scenario.duration_s);
    w.value("wall_s", wall_s);
    w.value("real_time_factor", scenario.corners.scenario.duration_s / wall_s);
    w.value("exchange_every_samples", exchange_every);
    w.value("feedback", feedback.empty() ? std::string("scenario") : feedback);
    w.begin_array("processes");
    for (const auto& p : scenario.processes) w.value("", p);
    w.end_array();
    bbw::vehicle_run::write_vehicle_json(w, m);
    {
      const auto err = bbw::vehicle_run::clamp_force_error(run);
      w.begin_object("clamp_force_error");  // (F_true - F_cmd) / F_cmd, mean over the stop
      const char* names[4] = {"FL", "FR", "RL", "RR"};
      for (std::size_t i = 0; i < 4; ++i) w.value(names[i], err[i]);
      w.end_object();
      w.begin_object("fits_accepted");  // the CCU's calibrator per corner
      for (std::size_t i = 0; i < 4; ++i) {
        w.value(names[i], static_cast<long long>(run.in_process().ccu().core().supervisor(i).calibrator().stats().fits_accepted));
      }
      w.end_object();
    }
    w.end_object();
    w.save(out_dir + "/summary.json");
    if (want_plots) bbw::vehicle_run::write_vehicle_plots(out_dir, scenario.name);
    std::printf("%s: stopping distance %.2f m (ideal %.2f m, ratio %.3f), epsilon %.3f, max lateral %.2f m, rtf %.1fx\n",
                scenario.name.c_str(), m.stopping_distance_m, m.ideal_stopping_distance_m, m.distance_ratio,
                m.adhesion_utilisation, m.max_lateral_deviation_m, scenario.corners.scenario.duration_s / wall_s);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bbw_vehicle_inproc: " << e.what() << "\n";
    return 1;
  }
}
