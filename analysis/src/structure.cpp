#include "bbw/analysis/structure.hpp"

#include <algorithm>
#include <limits>
#include <sstream>
#include <utility>

#include "bbw/analysis/residual_tests.hpp"

namespace bbw::analysis::detail {

double choose_delta_max(const Context& c, Spec s) {
  if (!c.opt.friction_thresholds.empty()) return c.opt.friction_thresholds.back();  // fixed, as online
  double best = std::numeric_limits<double>::infinity();
  double best_dm = c.opt.delta_max_fractions.front() * c.xrange;
  for (double f : c.opt.delta_max_fractions) {
    s.delta_max = f * c.xrange;
    const double r = search_rms(c, s);
    if (r < best) {
      best = r;
      best_dm = s.delta_max;
    }
  }
  return best_dm;
}

void choose_curve(const Context& c, Spec& spec) {
  std::vector<double> sorted = c.rec.position;
  std::sort(sorted.begin(), sorted.end());
  auto knots_for = [&](int nk) {
    std::vector<double> k;
    for (int j = 1; j <= nk; ++j) {
      const double q = sorted[static_cast<std::size_t>(static_cast<double>(c.n - 1) * j / (nk + 1))];
      k.push_back((2.0 * q - (c.xmax + c.xmin)) / c.xrange);
    }
    return k;
  };
  std::vector<std::pair<Spec, double>> scores;
  for (int nk : c.opt.curve_knots_grid) {
    Spec t = spec;
    t.knots = knots_for(nk);
    t.delta_max = choose_delta_max(c, t);
    const Design d = build(c, t);
    const double r = rms_of(c.y - d.x * fit(c, d, c.train), fit_rows(d, c.holdout));
    scores.emplace_back(t, r);
  }
  double best = std::numeric_limits<double>::infinity();
  for (const auto& sc : scores) best = std::min(best, sc.second);
  for (const auto& sc : scores)
    if (sc.second <= (1.0 + c.opt.curve_knots_tolerance) * best) {
      spec = sc.first;
      return;
    }
}

void test_structure(const Context& c, AnalysisResult& res) {
  const Recording& rec = c.rec;
  const AnalysisOptions& opt = c.opt;
  // Scored samples only: before the element states are known the rows are not fitted.
  const std::size_t first = std::min(res.final_errors.unscored_initial_samples, c.n - 1);
  const auto scored = [first](const Vec& v) { return Vec(v.begin() + static_cast<std::ptrdiff_t>(first), v.end()); };
  const Vec r = scored(res.residual_after);
  const WhitenessTest w = whiteness(r, opt.ljung_box_lags);
  {
    StructureFinding f;
    f.test = "whiteness";
    f.statistic = w.ljung_box_q;
    f.critical = w.critical_q;
    f.effect = w.noise_rms > 0.0 ? w.structured_rms / w.noise_rms : std::numeric_limits<double>::infinity();
    f.effect_threshold = opt.structure_min_signal_to_noise;
    f.significant = w.significant;
    f.flagged = f.significant && f.effect > f.effect_threshold;
    res.structure.push_back(f);
  }
  auto dep = [&](const Vec& by, const std::string& name) {
    const DependenceTest t = dependence(r, scored(by), opt.structure_bins, name);
    StructureFinding f;
    f.test = name;
    f.statistic = t.f_statistic;
    f.critical = t.f_critical;
    f.effect = t.eta2;
    f.effect_threshold = opt.structure_min_eta2;
    f.significant = t.significant;
    f.flagged = f.significant && f.effect > f.effect_threshold;
    res.structure.push_back(f);
  };
  dep(rec.position, "position");
  dep(rec.time_s, "time");
  dep(c.v, "velocity");
  dep(c.a, "acceleration");
  if (!rec.temperature.empty()) dep(rec.temperature, "temperature");
  for (const auto& ch : rec.channels) dep(ch.values, "channel:" + ch.name);
  for (const auto& f : res.structure) {
    if (!f.flagged) continue;
    res.unexplained_structure = true;
    std::ostringstream o;
    if (f.test == "whiteness")
      o << "residual is not white: Ljung-Box Q = " << f.statistic << " > " << f.critical
        << ", predictable part " << f.effect << " x the white-noise level";
    else
      o << "residual depends on " << f.test << ": eta^2 = " << f.effect << " (F = " << f.statistic << " > "
        << f.critical << ")";
    res.structure_notes.push_back(o.str());
  }
}

}  // namespace bbw::analysis::detail
