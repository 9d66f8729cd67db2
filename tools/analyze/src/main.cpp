// bbw_analyze: residual analysis of one recording (issue 6). See ./bbw analyze --help.
#include <chrono>
#include <exception>
#include <iostream>

#include "bbw/analysis/analysis.hpp"
#include "bbw/analyze/cli.hpp"
#include "bbw/analyze/config_loader.hpp"
#include "bbw/analyze/report.hpp"

int main(int argc, char** argv) {
  using namespace bbw;
  std::vector<std::string> args(argv + 1, argv + argc);
  for (const auto& a : args)
    if (a == "--help" || a == "-h") {
      std::cout << analyze::usage();
      return 0;
    }
  analyze::CliArgs cli;
  try {
    cli = analyze::parse_args(args);
  } catch (const std::invalid_argument& e) {
    std::cerr << "bbw_analyze: " << e.what() << "\n" << analyze::usage();
    return 2;
  }
  // From here on an error is one line (file:line: reason), without the usage text.
  try {
    auto opts = cli.config.empty() ? analysis::AnalysisOptions{} : analyze::load_options_file(cli.config);
    const auto in = analyze::load_recording(cli);
    opts.friction_thresholds = analyze::calibrator_friction_thresholds(cli.calibrator, in.position_unit);
    if (in.lines_rejected > 0 || in.lines_unsorted_time > 0) std::cerr << "bbw_analyze: " << in.file << ": " << in.rejection_summary << "\n";
    const auto t0 = std::chrono::steady_clock::now();
    const auto result = analysis::analyze(in.rec, opts);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    analyze::write_outputs(cli.out, in, opts, result);
    std::cout << "bbw_analyze: " << in.file << ": " << result.steps.size() << " effect(s) added";
    for (const auto& s : result.steps) std::cout << " [" << s.evidence.name << "]";
    std::cout << "; RMS residual " << result.baseline.rms_residual << " -> " << result.final_errors.rms_residual << " "
              << in.force_unit;
    if (result.baseline.has_truth)
      std::cout << "; max error vs truth " << result.baseline.max_truth_error << " -> "
                << result.final_errors.max_truth_error;
    std::cout << "; unexplained structure: " << (result.unexplained_structure ? "yes" : "no") << "; analysis "
              << secs << " s; wrote " << cli.out << "/analysis.json\n";
    return 0;
  } catch (const std::invalid_argument& e) {
    std::cerr << "bbw_analyze: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "bbw_analyze: " << e.what() << "\n";
    return 1;
  }
}
