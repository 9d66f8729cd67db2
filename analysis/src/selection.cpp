#include "bbw/analysis/selection.hpp"

#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include "bbw/analysis/bounded_lsq.hpp"

namespace bbw::analysis::detail {

double paired_t(const Eigen::VectorXd& r_old, const Eigen::VectorXd& r_new, const std::vector<Index>& rows, int blocks) {
  const std::size_t nb = static_cast<std::size_t>(blocks);
  if (rows.size() < nb * 2) return 0.0;
  Vec logs(nb, 0.0);
  for (std::size_t b = 0; b < nb; ++b) {
    const std::size_t lo = rows.size() * b / nb, hi = rows.size() * (b + 1) / nb;
    double so = 0.0, sn = 0.0;
    for (std::size_t k = lo; k < hi; ++k) {
      const Index i = rows[k];
      so += r_old(i) * r_old(i);
      sn += r_new(i) * r_new(i);
    }
    logs[b] = std::log((so + 1e-300) / (sn + 1e-300));
  }
  const double m = std::accumulate(logs.begin(), logs.end(), 0.0) / static_cast<double>(nb);
  double var = 0.0;
  for (double x : logs) var += (x - m) * (x - m);
  var /= static_cast<double>(nb - 1);
  if (var <= 0.0) return m > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
  return m / std::sqrt(var / static_cast<double>(nb));
}

std::vector<Candidate> candidates_for(const Context& c, const Spec& s) {
  std::vector<Candidate> out;
  auto has_column = [&](EffectKind k, int ch) {
    for (const auto& e : s.columns)
      if (e.kind == k && e.channel == ch) return true;
    return false;
  };
  const auto& o = c.opt;
  if (o.is_candidate("viscous_friction") && !has_column(EffectKind::ViscousFriction, -1))
    out.push_back({EffectKind::ViscousFriction, "viscous_friction"});
  if (o.is_candidate("load_dependent_friction") && !has_column(EffectKind::LoadDependentFriction, -1))
    out.push_back({EffectKind::LoadDependentFriction, "load_dependent_friction"});
  if (o.is_candidate("sensor_delay") && !s.has_delay) out.push_back({EffectKind::SensorDelay, "sensor_delay"});
  if (o.is_candidate("temperature_drift") && !c.rec.temperature.empty() && !has_column(EffectKind::TemperatureDrift, -1))
    out.push_back({EffectKind::TemperatureDrift, "temperature_drift"});
  if (o.is_candidate("backlash") && !s.has_backlash) out.push_back({EffectKind::Backlash, "backlash"});
  if (o.is_candidate("creep") && !has_column(EffectKind::Creep, -1)) out.push_back({EffectKind::Creep, "creep"});
  if (o.is_candidate("inertia") && !has_column(EffectKind::Inertia, -1)) out.push_back({EffectKind::Inertia, "inertia"});
  for (std::size_t i = 0; i < c.rec.channels.size(); ++i) {
    const int ch = static_cast<int>(i);
    const std::string& nm = c.rec.channels[i].name;
    if (!has_column(EffectKind::Channel, ch)) out.push_back({EffectKind::Channel, "channel:" + nm, ch});
    if (!has_column(EffectKind::ChannelTimesVelocity, ch))
      out.push_back({EffectKind::ChannelTimesVelocity, "channel:" + nm + "*velocity", ch});
  }
  return out;
}

Spec with(const Spec& s, const Candidate& cand, double hyper) {
  Spec t = s;
  switch (cand.kind) {
    case EffectKind::SensorDelay:
      t.has_delay = true;
      t.delay_s = hyper;
      break;
    case EffectKind::Backlash:
      t.has_backlash = true;
      t.backlash_width = hyper;
      break;
    default:
      t.columns.push_back({cand.kind, cand.name, hyper, cand.channel});
  }
  return t;
}

Scored score_candidate(const Context& c, const Spec& s, const Candidate& cand, const Eigen::VectorXd& current_residual,
                       double current_holdout_rms) {
  Scored out;
  out.score.name = cand.name;
  Vec grid;
  if (cand.kind == EffectKind::SensorDelay) {
    out.score.hyper_name = "delay_s";
    for (double d : c.opt.delay_grid_s)
      if (std::abs(d) >= 0.5 * c.dt) grid.push_back(d);
  } else if (cand.kind == EffectKind::Backlash) {
    out.score.hyper_name = "width";
    for (double f : c.opt.backlash_width_fractions) grid.push_back(f * c.xrange);
  } else if (cand.kind == EffectKind::Creep) {
    out.score.hyper_name = "tau_s";
    grid = c.opt.creep_tau_s;
  }
  double hyper = 0.0;
  if (!grid.empty()) {
    double best = std::numeric_limits<double>::infinity();
    for (double h : grid) {
      const double r = search_rms(c, with(s, cand, h));
      if (r < best) {
        best = r;
        hyper = h;
      }
    }
  }
  out.score.hyper_value = hyper;
  out.spec = with(s, cand, hyper);
  const Design d = build(c, out.spec);
  const Eigen::VectorXd b = fit(c, d, c.train);
  const Eigen::VectorXd r = c.y - d.x * b;
  const std::vector<Index> held = fit_rows(d, c.holdout);  // states known
  out.score.holdout_rms = rms_of(r, held);
  out.score.relative_drop = 1.0 - out.score.holdout_rms / current_holdout_rms;
  out.score.t_statistic = paired_t(current_residual, r, held, c.opt.significance_blocks);
  out.score.significant =
      out.score.relative_drop >= c.opt.min_relative_drop && out.score.t_statistic >= c.opt.min_t_statistic;
  out.score.rejected_reason = physical_bounds_violation(c, out.spec, d, b, cand.name);
  if (!out.score.rejected_reason.empty()) out.score.significant = false;
  return out;
}

void split_uncertainty(const Context& c, const Spec& s, const Evaluated& ev, Step& st) {
  const Design& d = ev.design;
  Index offset_col = -1;
  for (Index j = 0; j < d.x.cols(); ++j) {
    const int o = d.owner[static_cast<std::size_t>(j)];
    if (o >= 0 && s.columns[static_cast<std::size_t>(o)].kind == EffectKind::TemperatureDrift) {
      offset_col = j;
      break;
    }
  }
  if (offset_col < 0 || offset_col + 2 >= d.x.cols()) return;
  const Index shift_col = offset_col + 2;  // columns: offset, gain, shift
  const std::vector<Index> rows = fit_rows(d, c.train);
  const LsqProblem p = normal_equations(d.x, c.y, rows);
  const Eigen::VectorXd scale = p.gram.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd g = scale.asDiagonal() * p.gram * scale.asDiagonal();
  const Eigen::MatrixXd inv = g.ldlt().solve(Eigen::MatrixXd::Identity(g.rows(), g.cols()));
  const double corr = inv(offset_col, shift_col) / std::sqrt(inv(offset_col, offset_col) * inv(shift_col, shift_col));
  double rss = 0.0;
  for (Index k : rows) rss += ev.residual(k) * ev.residual(k);
  const double dof = std::max(1.0, static_cast<double>(rows.size()) - static_cast<double>(d.x.cols()));
  st.offset_shift_correlation = std::isfinite(corr) ? corr : 1.0;
  st.offset_standard_error = std::sqrt(rss / dof * inv(offset_col, offset_col)) * scale(offset_col);
  st.ambiguous = std::abs(st.offset_shift_correlation) >= AnalysisResult::kAmbiguousCorrelation;
}

std::string physical_bounds_violation(const Context& c, const Spec& s, const Design& d, const Eigen::VectorXd& b,
                                      const std::string& name) {
  Evaluated ev;
  ev.design = d;
  ev.coef = b;
  auto ends_with = [](const std::string& a, const std::string& tail) {
    return a.size() >= tail.size() && a.compare(a.size() - tail.size(), tail.size(), tail) == 0;
  };
  for (const auto& p : effect_parameters(model_parameters(c, s, ev), name)) {
    std::string rule;
    if (ends_with(p.name, ".unrelaxed_fraction") && !(p.value >= 0.0 && p.value < 1.0)) rule = "must be in [0, 1)";
    if ((ends_with(p.name, ".mass") || ends_with(p.name, ".delay_s") || ends_with(p.name, ".width") ||
         (name == "viscous_friction" && ends_with(p.name, ".coefficient"))) &&
        !(p.value >= 0.0)) {
      rule = "must be >= 0";
    }
    if (!rule.empty()) {
      std::ostringstream o;
      o << p.name << " = " << p.value << " " << rule;
      return o.str();
    }
  }
  return "";
}

}  // namespace bbw::analysis::detail
