#include "bbw/analysis/analysis.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "bbw/analysis/design.hpp"
#include "bbw/analysis/differentiate.hpp"
#include "bbw/analysis/selection.hpp"
#include "bbw/analysis/structure.hpp"

namespace bbw::analysis {

using namespace detail;

namespace {

void check(const Recording& rec) {
  const std::size_t n = rec.time_s.size();
  if (n < 200) throw std::invalid_argument("analyze: need at least 200 samples, got " + std::to_string(n));
  auto same = [&](const Vec& v, const char* what, bool optional) {
    if (optional && v.empty()) return;
    if (v.size() != n)
      throw std::invalid_argument(std::string("analyze: ") + what + " has " + std::to_string(v.size()) +
                                  " samples, time has " + std::to_string(n));
  };
  same(rec.position, "position", false);
  same(rec.force, "force", false);
  same(rec.truth, "truth", true);
  same(rec.temperature, "temperature", true);
  same(rec.velocity, "velocity", true);
  same(rec.acceleration, "acceleration", true);
  for (const auto& ch : rec.channels) same(ch.values, ch.name.c_str(), false);
  for (std::size_t k = 1; k < n; ++k)
    if (!(rec.time_s[k] > rec.time_s[k - 1]))
      throw std::invalid_argument("analyze: time is not increasing at sample " + std::to_string(k));
}

}  // namespace

AnalysisResult analyze(const Recording& raw, const AnalysisOptions& opt) {
  opt.validate();
  check(raw);
  Recording rec = raw;
  std::vector<std::string> outlier_where;
  const std::size_t outliers = reject_gross_outliers(rec, &outlier_where);
  Context c(rec, opt);
  c.n = rec.time_s.size();
  c.dt = (rec.time_s.back() - rec.time_s.front()) / static_cast<double>(c.n - 1);
  const auto [mn, mx] = std::minmax_element(rec.position.begin(), rec.position.end());
  c.xmin = *mn;
  c.xmax = *mx;
  c.xrange = c.xmax - c.xmin;
  if (!(c.xrange > 0.0)) throw std::invalid_argument("analyze: position is constant");
  c.y = Eigen::Map<const Eigen::VectorXd>(rec.force.data(), static_cast<Index>(c.n));
  if (!rec.temperature.empty()) {
    if (std::isfinite(opt.temperature_reference_C)) {
      c.temp_ref = opt.temperature_reference_C;
    } else {  // the load cell is taken as tared at the start: median of the first 100 samples
      std::vector<double> first(rec.temperature.begin(), rec.temperature.begin() + std::min<std::ptrdiff_t>(100, static_cast<std::ptrdiff_t>(c.n)));
      std::nth_element(first.begin(), first.begin() + static_cast<std::ptrdiff_t>(first.size() / 2), first.end());
      c.temp_ref = first[first.size() / 2];
    }
  }

  AnalysisResult res;
  res.gross_outliers = outliers;
  res.gross_outlier_samples = outlier_where;
  res.samples = c.n;
  res.dt_s = c.dt;
  std::ostringstream how;
  const std::size_t hv = half_width_for(opt.velocity_window_s, c.dt);
  const std::size_t ha = half_width_for(opt.acceleration_window_s, c.dt);
  if (rec.velocity.empty()) {
    c.v = sg_first_derivative(rec.position, c.dt, hv);
    how << "velocity: centred Savitzky-Golay (quadratic) first derivative of position over " << (2 * hv + 1)
        << " samples (" << (2 * hv + 1) * c.dt << " s); ";
  } else {
    c.v = rec.velocity;
    how << "velocity: recorded channel; ";
  }
  if (rec.acceleration.empty()) {
    c.a = sg_second_derivative(rec.position, c.dt, ha);
    how << "acceleration: centred Savitzky-Golay (quadratic) second derivative of position over " << (2 * ha + 1)
        << " samples (" << (2 * ha + 1) * c.dt << " s)";
  } else {
    c.a = rec.acceleration;
    how << "acceleration: recorded channel";
  }
  res.differentiator = how.str();

  // Held-out rows: whole blocks of the recording, split in time.
  const std::size_t blocks = opt.split == HoldoutSplit::Interleaved ? static_cast<std::size_t>(opt.split_blocks) : 1;
  std::vector<bool> held(c.n, false);
  if (opt.split == HoldoutSplit::Interleaved) {
    const auto h = static_cast<std::size_t>(std::lround(opt.holdout_fraction * static_cast<double>(blocks)));
    for (std::size_t j = 0; j < std::max<std::size_t>(h, 1); ++j) {
      const std::size_t b = static_cast<std::size_t>((static_cast<double>(j) + 0.5) * static_cast<double>(blocks) /
                                                     static_cast<double>(std::max<std::size_t>(h, 1)));
      for (std::size_t k = c.n * b / blocks; k < c.n * (b + 1) / blocks; ++k) held[k] = true;
    }
  } else {
    const auto start = static_cast<std::size_t>((1.0 - opt.holdout_fraction) * static_cast<double>(c.n));
    for (std::size_t k = start; k < c.n; ++k) held[k] = true;
  }
  double train_lo = std::numeric_limits<double>::infinity(), train_hi = -train_lo;
  for (std::size_t k = 0; k < c.n; ++k)
    if (!held[k]) {
      train_lo = std::min(train_lo, rec.position[k]);
      train_hi = std::max(train_hi, rec.position[k]);
    }
  for (std::size_t k = 0; k < c.n; ++k) {
    if (!held[k]) c.train.push_back(static_cast<Index>(k));
    else if (rec.position[k] >= train_lo && rec.position[k] <= train_hi) c.holdout.push_back(static_cast<Index>(k));
  }
  if (c.holdout.size() < static_cast<std::size_t>(4 * opt.significance_blocks))
    throw std::invalid_argument("analyze: too few held-out samples inside the fit part's position range");
  res.holdout_samples = c.holdout.size();
  const std::size_t step = (c.train.size() + static_cast<std::size_t>(opt.search_max_rows) - 1) /
                           static_cast<std::size_t>(opt.search_max_rows);
  for (std::size_t k = 0; k < c.train.size(); k += std::max<std::size_t>(step, 1)) c.train_search.push_back(c.train[k]);

  // Baseline: eq. 5 with Delta_max chosen on the fit part.
  Spec spec;
  choose_curve(c, spec);
  res.curve_knots = static_cast<int>(spec.knots.size());

  Evaluated cur = [&] {
    Design d = build(c, spec);
    Eigen::VectorXd b = fit(c, d, c.train);
    return evaluate(c, spec, std::move(d), b);
  }();
  update_refs(c, cur);
  res.baseline_delta_max = spec.delta_max;
  res.baseline_parameters = model_parameters(c, spec, cur);
  res.baseline = cur.errors;
  res.residual_before.assign(cur.residual.data(), cur.residual.data() + cur.residual.size());
  res.truth_error_before = cur.truth_error;

  std::vector<CandidateScore> earlier_bounds;  // earlier rounds' candidates refused for their bounds
  for (int round = 0; round <= opt.max_steps; ++round) {
    const auto cands = candidates_for(c, spec);
    if (cands.empty()) break;
    std::vector<Scored> scored;
    for (const auto& cand : cands)
      scored.push_back(score_candidate(c, spec, cand, cur.residual, cur.errors.holdout_rms_residual));
    std::sort(scored.begin(), scored.end(),
              [](const Scored& a, const Scored& b) { return a.score.holdout_rms < b.score.holdout_rms; });
    std::vector<CandidateScore> scores;
    for (const auto& s : scored) scores.push_back(s.score);
    res.rounds.push_back(scores);

    // The best significant candidate by held-out RMS.
    const Scored* best = nullptr;
    for (const auto& s : scored)
      if (s.score.significant) {
        best = &s;
        break;
      }
    if (!best || round == opt.max_steps) {
      res.rejected = scores;
      if (best) res.structure_notes.push_back("max_steps reached with a significant candidate left");
      break;
    }
    for (const auto& s : scored)
      if (!s.score.rejected_reason.empty()) earlier_bounds.push_back(s.score);
    Step st;
    st.evidence = best->score;
    for (const auto& s : scored)
      if (&s != best) {
        st.runner_up = s.score.name;
        st.runner_up_relative_drop = s.score.relative_drop;
        break;
      }
    spec = best->spec;
    choose_curve(c, spec);
    // Refit, refresh the curve/friction the columns are built on, and refit once more.
    for (int pass = 0; pass < 2; ++pass) {
      Design d = build(c, spec);
      Eigen::VectorXd b = fit(c, d, c.train);
      cur = evaluate(c, spec, std::move(d), b);
      update_refs(c, cur);
    }
    if (best->score.name == "temperature_drift") split_uncertainty(c, spec, cur, st);
    st.delta_max = spec.delta_max;
    st.curve_knots = static_cast<int>(spec.knots.size());
    st.parameters = effect_parameters(model_parameters(c, spec, cur), best->score.name);
    st.errors = cur.errors;
    if (res.steps.empty()) {
      const std::string& nm = best->score.name;
      res.display_regressor_name = nm == "inertia"                                   ? "acceleration (" + nm + ")"
                                   : nm == "viscous_friction" || nm == "sensor_delay" ? "velocity (" + nm + ")"
                                   : nm == "temperature_drift"                        ? "temperature (" + nm + ")"
                                   : nm == "backlash" ? "position - play(position) (backlash)"
                                                      : "regressor of " + nm;
      res.display_regressor = display_signal(c, spec, best->score.name);
    }
    res.steps.push_back(st);
  }
  res.rejected.insert(res.rejected.end(), earlier_bounds.begin(), earlier_bounds.end());
  res.final_parameters = model_parameters(c, spec, cur);
  res.final_errors = cur.errors;
  res.residual_after.assign(cur.residual.data(), cur.residual.data() + cur.residual.size());
  res.truth_error_after = cur.truth_error;
  res.velocity = c.v;
  if (res.steps.empty()) {
    res.display_regressor_name = "position";
    res.display_regressor = rec.position;
  }

  test_structure(c, res);
  return res;
}

std::vector<CalibratorTerm> calibrator_terms(const AnalysisResult& r) {
  std::vector<CalibratorTerm> out;
  for (const Step& s : r.steps) {
    if (s.evidence.name == "viscous_friction") out.push_back({"viscous_friction", 1.0});
    for (const Parameter& p : r.final_parameters) {
      if (s.evidence.name == "sensor_delay" && p.name == "sensor_delay.delay_s") out.push_back({"force_delay_s", p.value});
      if (s.evidence.name == "backlash" && p.name == "backlash.width") out.push_back({"backlash_width_rev", p.value});
      if (s.evidence.name == "load_dependent_friction") {
        if (p.name == "load_dependent_friction.friction_gain_at_full_curve") {
          out.push_back({"load_friction_gain", std::clamp(p.value, 0.0, 10.0)});
        }
        if (p.name == "load_dependent_friction.reference_force") out.push_back({"load_friction_reference_kN", p.value});
      }
      if (s.evidence.name == "temperature_drift" && !s.ambiguous) {
        if (p.name == "temperature_drift.sensor_offset_per_degC") {
          out.push_back({"load_cell_offset_kN_per_C", std::clamp(p.value, -1.0, 1.0)});
        }
        if (p.name == "temperature_drift.reference_temperature_C") out.push_back({"load_cell_offset_reference_C", p.value});
      }
    }
  }
  return out;
}

}  // namespace bbw::analysis
