// bbw_inproc SCENARIO.yaml --out DIR [--calibrator FILE] [--monitor FILE] [--friction-feedback on|off]
// The CCU node and one corner node per scenario corner over the in-memory transport, in one
// process and one thread, in lockstep: the same node cores and protocol as `./bbw run` over
// Fast DDS, so it writes the same logs (ccu_<corner>.csv, ccu_periods.csv,
// corner_<corner>_periods.csv; test InProcessSystem.LogsEqualTheDdsRun), and a summary.json
// with the run's real-time factor, and detections.csv (the fault monitor's detections). Process faults (kill, restart) need real processes: refused.
//
// Exit: 0 done, 1 runtime error, 2 bad arguments or config.
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/node/csv_log.hpp"
#include "bbw/node/in_process.hpp"
#include "bbw/tool_cli/tool_cli.hpp"

namespace {

constexpr const char* kUsage =
    "usage: bbw_inproc SCENARIO.yaml --out DIR [--calibrator FILE] [--monitor FILE] [--friction-feedback on|off]\n";

}  // namespace

int main(int argc, char** argv) {
  bbw::tool_cli::ModelArgs args;  // defaults from bbw's data (data_path.hpp)
  std::string out_dir;
  bbw::node::InProcessOptions options;
  const auto stop = bbw::tool_cli::parse(argc, argv, "bbw_inproc", kUsage, args, [&](const std::string& a, const auto& value) {
    if (a == "--out") out_dir = value();
    else if (a == "--friction-feedback") {
      const std::string v = value();
      if (v != "on" && v != "off") throw std::invalid_argument("--friction-feedback must be on or off, got '" + v + "'");
      options.friction_feedback = v == "on";
    } else return false;
    return true;
  });
  if (stop) return *stop;
  if (out_dir.empty()) return bbw::tool_cli::usage_error("bbw_inproc", kUsage, "--out DIR is required");
  const std::string& scenario_file = args.scenario;

  try {
    auto fs = bbw::faults::load_fault_scenario(scenario_file);
    options.schedule = fs.faults;
    const auto calibrator = bbw::tool_cli::load_calibrator(args);
    options.monitor = bbw::tool_cli::load_monitor(args);
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec || !std::filesystem::is_directory(out_dir)) {
      throw std::invalid_argument(out_dir + ": cannot create output directory" + (ec ? " (" + ec.message() + ")" : ""));
    }

    bbw::node::InProcessRun run(fs.scenario, calibrator, options);
    bbw::node::CcuCsvLog ccu_log(out_dir, run.ccu());
    run.ccu().set_observer(&ccu_log);
    std::vector<std::unique_ptr<bbw::node::CornerPeriodsLog>> corner_logs;
    for (std::size_t i = 0; i < run.corners(); ++i) {
      const std::string name = bbw::corner_name(run.corner(i).corner());
      corner_logs.push_back(std::make_unique<bbw::node::CornerPeriodsLog>(out_dir + "/corner_" + name + "_periods.csv", 0));
      run.corner(i).set_observer(corner_logs.back().get());
    }
    const auto t0 = std::chrono::steady_clock::now();
    run.run();
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double sim_s = static_cast<double>(run.periods_done()) * fs.scenario.ccu_period_s;
    run.ccu().set_observer(nullptr);
    ccu_log.flush();
    for (auto& l : corner_logs) l->flush();

    const std::string summary = out_dir + "/summary.json";
    std::FILE* f = std::fopen(summary.c_str(), "w");
    if (f == nullptr) throw std::runtime_error(summary + ": cannot write");
    std::fprintf(f, "{\n  \"scenario\": \"%s\",\n  \"transport\": \"memory\",\n  \"mode\": \"lockstep\",\n"
                    "  \"periods\": %llu,\n  \"sim_s\": %.6f,\n  \"wall_s\": %.6f,\n  \"real_time_factor\": %.3f,\n  \"corners\": {",
                 fs.scenario.name.c_str(), static_cast<unsigned long long>(run.periods_done()), sim_s, wall_s,
                 wall_s > 0.0 ? sim_s / wall_s : 0.0);
    for (std::size_t i = 0; i < run.ccu().channels(); ++i) {
      const auto& ch = run.ccu().channel(i);
      const auto& st2 = run.ccu().core().supervisor(ch.slot).calibrator().stats();
      std::fprintf(f, "%s\n    \"%s\": {\"samples_received\": %llu, \"fits_accepted\": %llu, \"block_gaps\": %llu, \"sample_gaps\": %llu}",
                   i == 0 ? "" : ",", bbw::corner_name(ch.corner), static_cast<unsigned long long>(ch.samples_received),
                   static_cast<unsigned long long>(st2.fits_accepted), static_cast<unsigned long long>(ch.block_gaps),
                   static_cast<unsigned long long>(ch.sample_gaps));
    }
    std::fprintf(f, "\n  },\n  \"detections\": %zu\n}\n", run.ccu().detections().size());
    if (std::fclose(f) != 0) throw std::runtime_error(summary + ": write failed");
    // The fault monitor's detections (as ccu.stats holds them after a DDS run, at full precision:
    // a scorer compares them with the logs' times), for scorers.
    {
      const std::string file = out_dir + "/detections.csv";
      std::FILE* d = std::fopen(file.c_str(), "w");
      if (d == nullptr) throw std::runtime_error(file + ": cannot write");
      std::fprintf(d, "corner,finding,onset_s,detected_s\n");
      for (const auto& r : run.ccu().detections()) {
        std::fprintf(d, "%s,%s,%.17g,%.17g\n", bbw::faults::to_string(static_cast<bbw::faults::Target>(r.slot)),
                     bbw::faults::to_string(r.finding), r.onset_s, r.detected_s);
      }
      if (std::fclose(d) != 0) throw std::runtime_error(file + ": write failed");
    }
    std::cout << "bbw_inproc: " << fs.scenario.name << ", " << run.periods_done() << " periods, " << sim_s << " s simulated in "
              << wall_s << " s (" << (wall_s > 0.0 ? sim_s / wall_s : 0.0) << "x real time); logs in " << out_dir << "\n";
  } catch (const std::invalid_argument& e) {
    std::cerr << "bbw_inproc: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "bbw_inproc: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
