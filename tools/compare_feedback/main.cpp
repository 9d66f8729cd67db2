// bbw_compare_feedback: the vehicle-stop comparison of issue 4. Runs a demand scenario through
// bbw_launch twice, with the corners' friction-compensated load-cell feedback off (the CCU never
// enables it: raw load cell) and on, and writes DIR/summary.json comparing the true clamp
// force's tracking error per corner (all force-command samples, and holds only).
//   ./bbw compare-feedback SCENARIO.yaml --out DIR [--mode lockstep|realtime] [--domain N]
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "bbw/common/json.hpp"
#include "summary_reader.hpp"

namespace {

using bbw::compare_feedback::read_summary;
using bbw::compare_feedback::Tracking;

const char* kUsage = "usage: bbw_compare_feedback SCENARIO.yaml --out DIR [--mode lockstep|realtime] [--domain N]\n";

int run_launch(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    execv(argv[0], argv.data());
    std::perror("bbw_compare_feedback: exec bbw_launch");
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

int main(int argc, char** argv) {
  std::string scenario, out, mode = "lockstep", domain;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bbw_compare_feedback: missing value after " << k << "\n" << kUsage;
        std::exit(2);
      }
      return argv[++i];
    };
    if (k == "--out") out = next();
    else if (k == "--mode") mode = next();
    else if (k == "--domain") domain = next();
    else if (k == "-h" || k == "--help") { std::cout << kUsage; return 0; }
    else if (!k.empty() && k[0] == '-') { std::cerr << "bbw_compare_feedback: unknown argument '" << k << "'\n" << kUsage; return 2; }
    else scenario = k;
  }
  if (scenario.empty() || out.empty()) {
    std::cerr << "bbw_compare_feedback: a scenario and --out DIR are required\n" << kUsage;
    return 2;
  }
  std::filesystem::create_directories(out);
  std::map<std::string, std::map<std::string, Tracking>> runs;
  for (const std::string fb : {"off", "on"}) {
    const std::string dir = out + "/feedback_" + fb;
    std::vector<std::string> args = {BBW_LAUNCH_PATH, scenario, "--out", dir, "--mode", mode, "--friction-feedback", fb};
    if (!domain.empty()) {
      args.push_back("--domain");
      args.push_back(domain);
    }
    const int rc = run_launch(args);
    if (rc != 0) {
      std::cerr << "bbw_compare_feedback: the run with feedback " << fb << " failed (bbw_launch exit " << rc
                << "); its logs are in " << dir << "\n";
      return 1;
    }
    try {
      runs[fb] = read_summary(dir + "/summary.json");
    } catch (const std::exception& e) {
      std::cerr << "bbw_compare_feedback: " << dir << "/summary.json: " << e.what() << "\n";
      return 1;
    }
  }
  bbw::json::Writer j;
  j.begin_object();
  j.value("scenario", scenario).value("mode", mode);
  j.value("feedback_off_run", out + "/feedback_off").value("feedback_on_run", out + "/feedback_on");
  j.begin_array("corners");
  std::printf("%-4s %28s %28s\n", "", "tracking RMS off -> on [kN]", "holds RMS off -> on [kN]");
  for (const auto& [corner, off] : runs["off"]) {
    const Tracking& on = runs["on"][corner];
    j.begin_object()
        .value("corner", corner)
        .value("fits_accepted", on.fits)
        .value("tracking_rms_error_off_kN", off.rms)
        .value("tracking_rms_error_on_kN", on.rms)
        .value("tracking_max_abs_error_off_kN", off.max)
        .value("tracking_max_abs_error_on_kN", on.max)
        .value("tracking_steady_rms_error_off_kN", off.steady_rms)
        .value("tracking_steady_rms_error_on_kN", on.steady_rms)
        .value("tracking_steady_max_abs_error_off_kN", off.steady_max)
        .value("tracking_steady_max_abs_error_on_kN", on.steady_max)
        .end_object();
    std::printf("%-4s %13.3f -> %-12.3f %13.3f -> %-12.3f\n", corner.c_str(), off.rms, on.rms, off.steady_rms,
                on.steady_rms);
  }
  j.end_array().end_object();
  j.save(out + "/summary.json");
  std::printf("bbw_compare_feedback: %s/summary.json\n", out.c_str());
  return 0;
}
