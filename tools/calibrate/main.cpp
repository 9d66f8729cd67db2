// bbw_calibrate: the calibrator offline over a CSV recording (./bbw calibrate).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <cstring>
#include <iostream>
#include <string>

#include "bbw/common/data_path.hpp"
#include "bbw/calibration/config_yaml.hpp"
#include "bbw/calibration/offline.hpp"
#include "bbw/common/csv.hpp"
#include "bbw/common/json.hpp"
#include "bbw/common/plot.hpp"

namespace {

const char* kUsage =
    "usage: bbw_calibrate --input FILE.csv [--config FILE.yaml] --out DIR\n"
    "                     [--time COL] [--position COL] [--force COL] [--truth COL] [--speed COL]\n"
    "                     [--temperature COL] [--allow-unsorted-time]\n"
    "  Runs the calibrator over a recording. Default columns: time_s, position_rev,\n"
    "  force_internal_kN; truth: force_external_kN, speed: speed_rev_per_s (or the older speed_rev_s) and temperature: temperature_C when present.\n"
    "  Time must increase strictly; --allow-unsorted-time drops the lines where it does not and counts them.\n"
    "  Exit: 0 calibrated, 1 an error or no fit accepted (summary.json says why), 2 bad arguments.\n";

struct Args {
  std::string input, config, out;  // config default: config/calibrator/robust.yaml of bbw's data
  std::string time_col = "time_s", position_col = "position_rev", force_col = "force_internal_kN";
  std::string truth_col, speed_col, temperature_col;
  bool truth_given = false, speed_given = false, temperature_given = false;
  bool allow_unsorted_time = false;
};

bool parse(int argc, char** argv, Args& a) {
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto next = [&](std::string& dst) {
      if (i + 1 >= argc) throw std::invalid_argument("missing value after " + k);
      dst = argv[++i];
    };
    if (k == "--input") next(a.input);
    else if (k == "--config") next(a.config);
    else if (k == "--out") next(a.out);
    else if (k == "--time") next(a.time_col);
    else if (k == "--position") next(a.position_col);
    else if (k == "--force") next(a.force_col);
    else if (k == "--truth") { next(a.truth_col); a.truth_given = true; }
    else if (k == "--speed") { next(a.speed_col); a.speed_given = true; }
    else if (k == "--temperature") { next(a.temperature_col); a.temperature_given = true; }
    else if (k == "--allow-unsorted-time") a.allow_unsorted_time = true;
    else if (k == "-h" || k == "--help") { std::cout << kUsage; std::exit(0); }
    else throw std::invalid_argument("unknown argument '" + k + "'");
  }
  if (a.input.empty()) throw std::invalid_argument("--input is required");
  if (a.out.empty()) throw std::invalid_argument("--out is required");
  return true;
}

// has_scored: some sample was scored (a fit was accepted); without one the error plot has no
// point and gnuplot refuses it, so it is left out.
void write_plots(const std::string& dir, bool has_truth, bool has_scored) {
  using bbw::plot::quote;
  const std::string est = quote(dir + "/estimates.csv");
  const std::string pf = quote(dir + "/curve.csv");
  std::string s = "set datafile separator ','\nset terminal pngcairo size 1000,700\nset key top left\nset grid\n";
  s += "set output " + quote(dir + "/force_position.png") + "\n";
  s += "set xlabel 'position [rev]'\nset ylabel 'force [kN]'\nset title 'Force against position with the calibrated curve (Figs. 5, 10)'\n";
  s += "plot " + est + " using 2:3 every 5 with dots lc rgb '#1f77b4' title 'internal load cell'";
  if (has_truth) s += ", " + est + " using 2:7 every 5 with dots lc rgb '#2ca02c' title 'truth'";
  s += ", " + pf + " using 1:2 with lines lw 2 lc rgb '#d62728' title 'calibrated curve'\n";
  s += "set output " + quote(dir + "/estimate_time.png") + "\n";
  s += "set xlabel 'time [s]'\nset title 'Clamp-force estimate and truth against time (Fig. 15)'\n";
  s += "plot " + est + " using 1:4 with lines lc rgb '#1f77b4' title 'estimate'";
  if (has_truth) s += ", " + est + " using 1:7 with lines lc rgb '#2ca02c' title 'truth'";
  s += "\n";
  if (has_truth && has_scored) {
    s += "set output " + quote(dir + "/error_time.png") + "\n";
    s += "set ylabel 'error [kN]'\nset title 'Estimate error against time, scored after warm-up (Fig. 16)'\n";
    s += "plot " + est + " using 1:($10 > 0 ? $8 : 1/0) with lines lc rgb '#d62728' title 'estimate - truth'\n";
  }
  bbw::plot::run_gnuplot(s, dir + "/plots.gp");
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  try {
    parse(argc, argv, a);
  } catch (const std::exception& e) {
    std::cerr << "bbw_calibrate: " << e.what() << "\n" << kUsage;
    return 2;
  }
  try {
    if (a.config.empty()) a.config = bbw::data::path("config/calibrator/robust.yaml");
    const auto config = bbw::calibration::load_config(a.config);
    bbw::csv::ReadOptions ro;
    ro.required = {a.time_col, a.position_col, a.force_col};
    if (a.truth_given) ro.required.push_back(a.truth_col);
    else ro.optional.push_back("force_external_kN");
    if (a.speed_given) ro.required.push_back(a.speed_col);
    else ro.optional.insert(ro.optional.end(), {"speed_rev_per_s", "speed_rev_s"});  // the older spelling too
    if (a.temperature_given) ro.required.push_back(a.temperature_col);
    else ro.optional.push_back("temperature_C");
    ro.time_column = a.time_col;
    ro.allow_unsorted_time = a.allow_unsorted_time;
    const auto table = bbw::csv::read(a.input, ro);
    if (table.lines_rejected > 0 || table.lines_unsorted_time > 0) {
      std::cerr << "bbw_calibrate: " << a.input << ": " << table.rejection_summary() << "\n";
    }
    const std::string truth_col = a.truth_given ? a.truth_col : (table.has("force_external_kN") ? "force_external_kN" : "");

    bbw::calibration::Recording rec;
    rec.time_s = table.column(a.time_col);
    rec.position_rev = table.column(a.position_col);
    rec.force_kN = table.column(a.force_col);
    if (!truth_col.empty()) rec.truth_kN = table.column(truth_col);
    const std::string speed_col = a.speed_given                      ? a.speed_col
                                  : table.has("speed_rev_per_s") ? "speed_rev_per_s"
                                  : table.has("speed_rev_s")     ? "speed_rev_s"
                                                                 : "";
    if (!speed_col.empty()) rec.speed_rev_per_s = table.column(speed_col);
    const std::string temp_col =
        a.temperature_given ? a.temperature_col : (table.has("temperature_C") ? "temperature_C" : "");
    if (!temp_col.empty()) rec.temperature_C = table.column(temp_col);
    const auto res = bbw::calibration::run_recording(config, rec);

    std::error_code ec;
    std::filesystem::create_directories(a.out, ec);
    if (!std::filesystem::is_directory(a.out)) throw std::runtime_error(a.out + ": cannot create output directory");
    const bool has_truth = !rec.truth_kN.empty();
    {
      bbw::csv::Writer w(a.out + "/estimates.csv",
                         {"time_s", "position_rev", "force_internal_kN", "estimate_kN", "friction_kN", "curve_kN",
                          "truth_kN", "error_kN", "valid", "scored"});
      const double t_fit = res.stats.first_fit_time_s;
      for (std::size_t k = 0; k < res.estimates.size(); ++k) {
        const auto& e = res.estimates[k];
        const double truth = has_truth ? rec.truth_kN[k] : std::nan("");
        const bool scored = has_truth && e.valid && t_fit >= 0.0 && rec.time_s[k] >= t_fit;
        const double row[] = {rec.time_s[k], rec.position_rev[k], rec.force_kN[k], e.force_kN, e.friction_kN,
                              e.curve_force_kN, truth, has_truth ? e.force_kN - truth : std::nan(""),
                              e.valid ? 1.0 : 0.0, scored ? 1.0 : 0.0};
        w.row(row, 10);
      }
      w.close();
    }
    {
      bbw::csv::Writer w(a.out + "/curve.csv", {"position_rev", "force_kN"});
      const int n = 200;
      for (int k = 0; k <= n; ++k) {
        const double x = config.x_min_rev + (config.x_max_rev - config.x_min_rev) * k / n;
        const double row[] = {x, res.curve.force_kN(x)};
        w.row(row, 2);
      }
      w.close();
    }
    // Honest outcome: no accepted fit is a failed calibration; an error over no scored sample
    // is not a number (null in JSON), and the summary says why.
    std::string failure;
    if (res.stats.fits_accepted == 0) {
      failure = "no fit accepted (" + std::to_string(res.stats.cycles_detected) + " cycles detected, " +
                std::to_string(res.stats.fits_rejected) + " fits rejected, " + std::to_string(rec.time_s.size()) +
                " samples): the recording does not excite a calibration cycle";
    }
    std::string not_scored;
    if (!has_truth) not_scored = "no truth column";
    else if (res.score.samples_scored == 0) {
      not_scored = res.stats.fits_accepted == 0 ? "no fit accepted, so no estimate to score"
                                                : "no valid estimate after the first accepted fit";
    }
    const double nan = std::nan("");
    bbw::json::Writer j;
    j.begin_object();
    j.value("status", failure.empty() ? "calibrated" : "failed");
    if (!failure.empty()) j.value("reason", failure);
    j.value("input", a.input).value("config", a.config).value("mode", bbw::calibration::to_string(config.mode));
    j.value("samples", rec.time_s.size()).value("lines_rejected", table.lines_rejected);
    j.value("lines_unsorted_time_dropped", table.lines_unsorted_time);
    j.value("samples_rejected_by_calibrator", static_cast<long long>(res.stats.samples_rejected));
    j.value("truth_column", truth_col);
    if (has_truth) {
      const bool scored = not_scored.empty();
      j.value("max_abs_error_kN", scored ? res.score.max_abs_error_kN : nan)
          .value("rms_error_kN", scored ? res.score.rms_error_kN : nan);
      j.value("max_error_pct_fs", scored ? res.score.max_error_pct_fs : nan)
          .value("time_of_max_error_s", scored ? res.score.time_of_max_error_s : nan);
    }
    if (!not_scored.empty()) j.value("not_scored_reason", not_scored);
    j.value("full_scale_kN", config.full_scale_kN);
    j.value("samples_scored", res.score.samples_scored).value("warmup_s", res.score.warmup_s);
    j.value("cycles_detected", static_cast<long long>(res.stats.cycles_detected));
    j.value("fits_accepted", static_cast<long long>(res.stats.fits_accepted));
    j.value("fits_rejected", static_cast<long long>(res.stats.fits_rejected));
    j.begin_object("curve")
        .value("a_kN_per_rev3", res.curve.a).value("b_kN_per_rev2", res.curve.b)
        .value("c_kN_per_rev", res.curve.c).value("d_kN", res.curve.d)
        .end_object();
    j.begin_object("friction")
        .numbers("delta_rev", res.friction.delta_rev)
        .numbers("stiffness_kN_per_rev", res.friction.stiffness_kN_per_rev)
        .value("viscous_enabled", config.viscous_friction)
        .value("viscous_kN_per_rev_per_s", res.friction.viscous_kN_per_rev_per_s)
        .end_object();
    j.end_object();
    j.save(a.out + "/summary.json");
    if (!failure.empty()) {
      std::cerr << "bbw_calibrate: " << a.input << ": calibration failed: " << failure << " (wrote " << a.out
                << "/summary.json, no plots)\n";
      return 1;
    }
    try {
      write_plots(a.out, has_truth, res.score.samples_scored > 0);
    } catch (const std::exception& e) {
      std::cerr << "bbw_calibrate: plots: " << e.what() << " (summary.json and the CSV files are written)\n";
      return 1;
    }
    std::printf("bbw_calibrate: %s mode, %zu samples, %llu cycles, %llu fits accepted, %llu rejected",
                bbw::calibration::to_string(config.mode), rec.time_s.size(),
                static_cast<unsigned long long>(res.stats.cycles_detected),
                static_cast<unsigned long long>(res.stats.fits_accepted),
                static_cast<unsigned long long>(res.stats.fits_rejected));
    if (has_truth && not_scored.empty()) {
      std::printf(", max |error| %.4f kN (%.3f %% FS), RMS %.4f kN", res.score.max_abs_error_kN,
                  res.score.max_error_pct_fs, res.score.rms_error_kN);
    } else if (has_truth) {
      std::printf(", error not scored (%s)", not_scored.c_str());
    }
    std::printf("\nbbw_calibrate: wrote %s/summary.json, estimates.csv and plots\n", a.out.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bbw_calibrate: " << e.what() << "\n";
    return 1;
  }
}
