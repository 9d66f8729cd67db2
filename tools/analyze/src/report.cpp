#include "bbw/analyze/report.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "bbw/common/csv.hpp"
#include "bbw/common/json.hpp"
#include "bbw/common/plot.hpp"

namespace bbw::analyze {

namespace {

void errors_json(json::Writer& w, const std::string& key, const analysis::ErrorFigures& e, const std::string& unit) {
  w.begin_object(key);
  w.value("force_unit", unit);
  w.value("rms_residual", e.rms_residual);
  w.value("max_residual", e.max_residual);
  w.value("holdout_rms_residual", e.holdout_rms_residual);
  w.value("unscored_initial_samples", e.unscored_initial_samples);  // left out of the max figures
  if (e.has_truth) {
    w.value("rms_truth_error", e.rms_truth_error);
    w.value("max_truth_error", e.max_truth_error);
  }
  w.end_object();
}

void params_json(json::Writer& w, const std::string& key, const std::vector<analysis::Parameter>& ps) {
  w.begin_array(key);
  for (const auto& p : ps) {
    w.begin_object();
    w.value("name", p.name);
    w.value("value", p.value);
    w.value("unit", p.unit);
    w.end_object();
  }
  w.end_array();
}

void score_json(json::Writer& w, const analysis::CandidateScore& s) {
  w.value("name", s.name);
  if (!s.hyper_name.empty()) w.value(s.hyper_name, s.hyper_value);
  w.value("holdout_rms", s.holdout_rms);
  w.value("relative_drop", s.relative_drop);
  w.value("t_statistic", s.t_statistic);
  w.value("significant", s.significant);
  if (!s.rejected_reason.empty()) w.value("rejected_reason", s.rejected_reason);
}

std::string fmt(double v, int prec = 4) {
  std::ostringstream o;
  o << std::setprecision(prec) << v;
  return o.str();
}

}  // namespace

std::string analysis_json(const LoadedRecording& in, const analysis::AnalysisOptions& o,
                          const analysis::AnalysisResult& r) {
  json::Writer w;
  w.begin_object();
  w.begin_object("input");
  w.value("file", in.file);
  w.value("time", in.time_col);
  w.value("position", in.position_col);
  w.value("force", in.force_col);
  w.value("truth", in.truth_col);
  w.value("temperature", in.temperature_col);
  w.begin_array("channels");
  for (const auto& c : in.channel_cols) w.value("", c);
  w.end_array();
  w.value("lines_read", in.lines_read);
  w.value("lines_rejected", in.lines_rejected);
  w.value("lines_unsorted_time_dropped", in.lines_unsorted_time);
  w.value("samples", r.samples);
  w.value("dt_s", r.dt_s);
  w.value("holdout_samples", r.holdout_samples);
  w.value("gross_outliers", r.gross_outliers);  // replaced by the previous good value, not fitted
  w.begin_array("gross_outlier_samples");
  for (const auto& g : r.gross_outlier_samples) w.value("", g);
  w.end_array();
  w.end_object();
  w.value("force_unit", in.force_unit);
  w.value("position_unit", in.position_unit);
  w.begin_object("method");
  w.value("model", "eq. 5: cubic in position scaled to [-1,1] + Maxwell-slip friction, geometric thresholds, K_i >= 0 (active-set NNLS), element states streamed over every sample");
  if (o.friction_thresholds.empty()) {
    w.value("elements_M", o.elements_M);
    w.value("geometric_ratio", o.geometric_ratio);
    w.value("delta_max_rule", "grid over fractions of the position range, minimum fit-part RMS; re-chosen after every step");
  } else {
    w.value("elements_M", static_cast<int>(o.friction_thresholds.size()));
    w.value("delta_max_rule", "the online calibrator's element set (calibration::friction_thresholds_rev of its config), fixed");
    w.begin_array("friction_thresholds");
    for (double d : o.friction_thresholds) w.value("", d);
    w.end_array();
  }
  w.value("differentiator", r.differentiator);
  w.value("holdout", o.split == analysis::HoldoutSplit::Interleaved ? "interleaved blocks" : "tail");
  w.value("holdout_fraction", o.holdout_fraction);
  w.value("acceptance_rule", "held-out RMS drops by >= min_relative_drop and paired t of held-out squared-error improvement (block means) >= min_t_statistic");
  w.value("min_relative_drop", o.min_relative_drop);
  w.value("min_t_statistic", o.min_t_statistic);
  w.begin_array("sensor_effects");
  w.value("", "maxwell_slip_friction");
  for (const auto& s : o.sensor_effects) w.value("", s);
  w.end_array();
  w.end_object();
  w.value("curve_knots", r.curve_knots);
  w.value("baseline_delta_max", r.baseline_delta_max);
  params_json(w, "baseline_parameters", r.baseline_parameters);
  errors_json(w, "baseline", r.baseline, in.force_unit);
  errors_json(w, "final", r.final_errors, in.force_unit);
  w.begin_array("steps");
  for (const auto& s : r.steps) {
    w.begin_object();
    w.value("name", s.evidence.name);
    w.begin_object("evidence");
    score_json(w, s.evidence);
    w.value("runner_up", s.runner_up);
    w.value("runner_up_relative_drop", s.runner_up_relative_drop);
    w.end_object();
    params_json(w, "parameters", s.parameters);
    if (s.evidence.name == "temperature_drift") {
      // Load-cell offset versus the curve's shift with temperature: can they be told apart?
      w.value("ambiguous", s.ambiguous);
      w.value("offset_shift_correlation", s.offset_shift_correlation);
      w.value("offset_standard_error", s.offset_standard_error);
    }
    w.value("delta_max", s.delta_max);
    w.value("curve_knots", s.curve_knots);
    errors_json(w, "errors_after", s.errors, in.force_unit);
    w.end_object();
  }
  w.end_array();
  // What to switch on in the online calibrator's config (`effects:`), docs/calibrator.md.
  w.begin_object("calibrator_effects");
  for (const auto& t : analysis::calibrator_terms(r)) {
    if (t.key == "viscous_friction") w.value(t.key, true);
    else w.value(t.key, t.value);
  }
  w.end_object();
  w.begin_array("rejected");
  for (const auto& s : r.rejected) {
    w.begin_object();
    score_json(w, s);
    w.end_object();
  }
  w.end_array();
  w.begin_array("rounds");
  for (const auto& round : r.rounds) {
    w.begin_array();
    for (const auto& s : round) {
      w.begin_object();
      score_json(w, s);
      w.end_object();
    }
    w.end_array();
  }
  w.end_array();
  params_json(w, "final_parameters", r.final_parameters);
  w.value("unexplained_structure", r.unexplained_structure);
  w.begin_array("structure_tests");
  for (const auto& f : r.structure) {
    w.begin_object();
    w.value("test", f.test);
    w.value("statistic", f.statistic);
    w.value("critical", f.critical);
    w.value("effect", f.effect);
    w.value("effect_threshold", f.effect_threshold);
    w.value("significant", f.significant);
    w.value("flagged", f.flagged);
    w.end_object();
  }
  w.end_array();
  w.begin_array("structure_notes");
  for (const auto& s : r.structure_notes) w.value("", s);
  w.end_array();
  w.end_object();
  return w.str();
}

void write_outputs(const std::string& dir, const LoadedRecording& in, const analysis::AnalysisOptions& o,
                   const analysis::AnalysisResult& r, bool plots) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  {
    std::ofstream f(dir + "/analysis.json");
    if (!f) throw std::runtime_error(dir + "/analysis.json: cannot write");
    f << analysis_json(in, o, r) << "\n";
  }
  const bool truth = r.baseline.has_truth;
  {
    std::vector<std::string> cols = {"time_s", "regressor", "residual_before", "residual_after"};
    if (truth) {
      cols.push_back("truth_error_before");
      cols.push_back("truth_error_after");
    }
    csv::Writer wr(dir + "/plot_data.csv", cols);
    const std::size_t step = std::max<std::size_t>(1, r.samples / 20000);
    std::vector<double> row(cols.size());
    for (std::size_t k = 0; k < r.samples; k += step) {
      row[0] = in.rec.time_s[k];
      row[1] = r.display_regressor[k];
      row[2] = r.residual_before[k];
      row[3] = r.residual_after[k];
      if (truth) {
        row[4] = r.truth_error_before[k];
        row[5] = r.truth_error_after[k];
      }
      wr.row(row);
    }
    wr.close();
  }
  const std::string u = in.force_unit.empty() ? "force unit" : in.force_unit;
  const std::string data = plot::quote(dir + "/plot_data.csv");
  if (plots) {
    std::ostringstream s;
    s << "set terminal pngcairo size 1000,700 noenhanced\nset output " << plot::quote(dir + "/residual_time.png") << "\n"
      << "set datafile separator ','\nset key autotitle columnhead\nset multiplot layout 2,1\n"
      << "set xlabel 'time [s]'\nset ylabel 'residual [" << u << "]'\n"
      << "set title 'residual before (eq. 5 baseline)'\nplot " << data << " using 1:3 with dots lc rgb '#c03030' notitle\n"
      << "set title 'residual after (final model)'\nplot " << data << " using 1:4 with dots lc rgb '#3030c0' notitle\n"
      << "unset multiplot\n";
    plot::run_gnuplot(s.str(), dir + "/residual_time.gp");
    std::ostringstream g;
    g << "set terminal pngcairo size 1000,700 noenhanced\nset output " << plot::quote(dir + "/residual_vs_regressor.png") << "\n"
      << "set datafile separator ','\nset multiplot layout 1,2\nset xlabel '" << r.display_regressor_name << "'\n"
      << "set ylabel 'residual [" << u << "]'\n"
      << "set title 'before'\nplot " << data << " using 2:3 with dots lc rgb '#c03030' notitle\n"
      << "set title 'after'\nplot " << data << " using 2:4 with dots lc rgb '#3030c0' notitle\n"
      << "unset multiplot\n";
    plot::run_gnuplot(g.str(), dir + "/residual_vs_regressor.gp");
    if (truth) {
      std::ostringstream t;
      t << "set terminal pngcairo size 1000,500 noenhanced\nset output " << plot::quote(dir + "/truth_error_time.png") << "\n"
        << "set datafile separator ','\nset xlabel 'time [s]'\nset ylabel 'estimate - truth [" << u << "]'\n"
        << "plot " << data << " using 1:5 with lines lc rgb '#c03030' title 'before', " << data
        << " using 1:6 with lines lc rgb '#3030c0' title 'after'\n";
      plot::run_gnuplot(t.str(), dir + "/truth_error_time.gp");
    }
  }

  std::ofstream md(dir + "/report.md");
  if (!md) throw std::runtime_error(dir + "/report.md: cannot write");
  md << "# Residual analysis of `" << in.file << "`\n\n";
  md << r.samples << " samples at dt = " << fmt(r.dt_s) << " s (" << in.lines_rejected << " of " << in.lines_read
     << " lines rejected); force `" << in.force_col << "` in " << u << ", position `" << in.position_col << "`";
  if (truth) md << ", truth `" << in.truth_col << "`";
  md << ". Held out: " << r.holdout_samples << " samples ("
     << (o.split == analysis::HoldoutSplit::Interleaved ? "interleaved blocks" : "tail") << ").\n\n";
  md << "Baseline: eq. 5 with " << (r.curve_knots == 0 ? std::string("a cubic curve") : "a cubic-spline curve with " + std::to_string(r.curve_knots) + " interior knots") << ", M = "
     << (o.friction_thresholds.empty() ? o.elements_M : static_cast<int>(o.friction_thresholds.size()))
     << " geometric elements, Delta_max = " << fmt(r.baseline_delta_max)
     << (o.friction_thresholds.empty() ? " (chosen by fit-part RMS). " : " (the online calibrator's element set). ") << r.differentiator << ".\n\n";
  md << "| | RMS residual | max residual | held-out RMS |" << (truth ? " RMS error vs truth | max error vs truth |" : "")
     << "\n|---|---|---|---|" << (truth ? "---|---|" : "") << "\n";
  auto row = [&](const std::string& name, const analysis::ErrorFigures& e) {
    md << "| " << name << " | " << fmt(e.rms_residual) << " | " << fmt(e.max_residual) << " | "
       << fmt(e.holdout_rms_residual) << " |";
    if (truth) md << " " << fmt(e.rms_truth_error) << " | " << fmt(e.max_truth_error) << " |";
    md << "\n";
  };
  row("baseline", r.baseline);
  for (const auto& s : r.steps) row("+ " + s.evidence.name, s.errors);
  row("final", r.final_errors);
  if (r.gross_outliers > 0) {
    md << "\n" << r.gross_outliers << " gross outlier(s) (more than 10 times the 0.5-99.5 % span outside it) "
       << "replaced by the previous good value before fitting; first:";
    for (const auto& g : r.gross_outlier_samples) md << " " << g;
    md << ".\n";
  }
  md << "\nThe fit, every figure and the structure tests leave out the " << r.final_errors.unscored_initial_samples
     << " samples before the position had travelled 2 Delta_max from its running extreme (the "
        "friction's initial state is unknown until then; baseline: "
     << r.baseline.unscored_initial_samples << ").\n";
  md << "\nAll figures in " << u << ".\n\n## Steps\n\n";
  if (r.steps.empty()) md << "No candidate met the acceptance rule.\n";
  for (const auto& s : r.steps) {
    md << "- **" << s.evidence.name << "**: held-out RMS " << fmt(s.evidence.holdout_rms) << " (drop "
       << fmt(100.0 * s.evidence.relative_drop, 3) << " %, t = " << fmt(s.evidence.t_statistic, 3) << "); runner-up "
       << s.runner_up << " (" << fmt(100.0 * s.runner_up_relative_drop, 3) << " %). Parameters:";
    for (const auto& p : s.parameters) md << " " << p.name << " = " << fmt(p.value) << " " << p.unit << ";";
    if (s.evidence.name == "temperature_drift") {
      md << (s.ambiguous ? " **Ambiguous split**: the load-cell offset and the curve's shift with temperature cannot be "
                           "told apart on this recording"
                         : " Offset and curve shift told apart")
         << " (correlation of the two coefficients " << fmt(s.offset_shift_correlation, 3)
         << ", offset standard error " << fmt(s.offset_standard_error, 3) << " per degC, a white-noise lower bound)"
         << (s.ambiguous ? "; no online term is proposed for it." : ".");
    }
    md << "\n";
  }
  const auto terms = analysis::calibrator_terms(r);
  md << "\n## Back into the online calibrator\n\n";
  if (terms.empty()) {
    md << "None of the accepted effects has an online calibrator term (available: viscous_friction, "
          "sensor_delay, backlash, load_dependent_friction, temperature_drift).\n";
  } else {
    md << "For a caliper recording (position in rev, force in kN), add to the calibrator config "
          "(docs/calibrator.md, \"Optional effect terms\"):\n\n```yaml\neffects:\n";
    for (const auto& t : terms) {
      md << "  " << t.key << ": " << (t.key == "viscous_friction" ? std::string("true") : fmt(t.value)) << "\n";
    }
    md << "```\n";
  }
  md << "\n## Rejected (last round, and earlier candidates outside physical bounds)\n\n"
        "| candidate | held-out RMS | drop | t | reason |\n|---|---|---|---|---|\n";
  for (const auto& s : r.rejected)
    md << "| " << s.name << (s.hyper_name.empty() ? "" : " (" + s.hyper_name + " = " + fmt(s.hyper_value) + ")")
       << " | " << fmt(s.holdout_rms) << " | " << fmt(100.0 * s.relative_drop, 3) << " % | "
       << fmt(s.t_statistic, 3) << " | " << (s.rejected_reason.empty() ? "not significant" : s.rejected_reason)
       << " |\n";
  md << "\n## Structure left in the final residual\n\n";
  md << (r.unexplained_structure ? "**Structure is left that no candidate explains.**\n\n"
                                 : "No structure above the thresholds is left.\n\n");
  md << "| test | statistic | critical | effect | threshold | flagged |\n|---|---|---|---|---|---|\n";
  for (const auto& f : r.structure)
    md << "| " << f.test << " | " << fmt(f.statistic) << " | " << fmt(f.critical) << " | " << fmt(f.effect) << " | "
       << fmt(f.effect_threshold) << " | " << (f.flagged ? "yes" : "no") << " |\n";
  for (const auto& n : r.structure_notes) md << "\n- " << n;
  md << "\n\n## Plots\n\n";
  if (plots) {
    md << "![residual vs time](residual_time.png)\n\n![residual vs " << r.display_regressor_name
       << "](residual_vs_regressor.png)\n";
    if (truth) md << "\n![estimate error vs time](truth_error_time.png)\n";
  } else {
    md << "Plots were not drawn (plots disabled).\n";
  }
}

}  // namespace bbw::analyze
