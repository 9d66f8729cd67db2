#include "bbw/analysis/analysis.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "bbw/analysis/bounded_lsq.hpp"
#include "bbw/analysis/differentiate.hpp"
#include "bbw/analysis/effects.hpp"
#include "bbw/analysis/residual_tests.hpp"
#include "bbw/model/maxwell_slip.hpp"
#include "bbw/model/states_known.hpp"

namespace bbw::analysis {

namespace {

using Index = Eigen::Index;
using Vec = std::vector<double>;

struct ColumnEffect {
  EffectKind kind;
  std::string name;   // report name
  double hyper = 0.0; // tau_s for creep
  int channel = -1;
};

// The model: eq. 5 on an effective position (delayed and/or through a play operator) plus
// extra columns.
struct Spec {
  double delta_max = 0.0;
  std::vector<double> knots;  // interior spline knots in scaled position; empty: eq. 5 cubic
  bool has_delay = false;
  double delay_s = 0.0;
  bool has_backlash = false;
  double backlash_width = 0.0;
  std::vector<ColumnEffect> columns;
};

struct Design {
  Eigen::MatrixXd x;
  std::vector<bool> nonneg;
  std::vector<int> owner;  // -2 curve, -1 friction, >= 0 index into Spec::columns
  Vec deltas;
  Vec x_eff;
};

struct Context {
  Context(const Recording& r, const AnalysisOptions& o) : rec(r), opt(o) {}
  const Recording& rec;
  const AnalysisOptions& opt;
  std::size_t n = 0;
  double dt = 0.0;
  double xmin = 0.0, xmax = 0.0, xrange = 0.0;
  Vec v, a;
  double temp_ref = 0.0;
  Eigen::VectorXd y;
  std::vector<Index> train, train_search, holdout;
  // From the last accepted fit: the curve and the friction, for columns built on them.
  Vec ref_curve, ref_friction, ref_slope;
  double ref_curve_scale = 1.0, ref_slope_scale = 1.0;
};

double rms_of(const Eigen::VectorXd& r, const std::vector<Index>& rows) {
  double s = 0.0;
  for (Index k : rows) s += r(k) * r(k);
  return rows.empty() ? 0.0 : std::sqrt(s / static_cast<double>(rows.size()));
}

std::vector<Vec> column_values(const Context& c, const ColumnEffect& e) {
  const std::size_t n = c.n;
  switch (e.kind) {
    case EffectKind::ViscousFriction: return {c.v};
    case EffectKind::Inertia: return {c.a};
    case EffectKind::LoadDependentFriction: {
      Vec col(n);
      for (std::size_t k = 0; k < n; ++k) col[k] = c.ref_friction[k] * c.ref_curve[k] / c.ref_curve_scale;
      return {col};
    }
    case EffectKind::TemperatureDrift: {
      // Load-cell offset (sensor), curve gain and curve shift (true force) with temperature.
      Vec off(n), gain(n), shift(n);
      for (std::size_t k = 0; k < n; ++k) {
        off[k] = c.rec.temperature[k] - c.temp_ref;
        gain[k] = off[k] * c.ref_curve[k] / c.ref_curve_scale;
        shift[k] = off[k] * c.ref_slope[k] / c.ref_slope_scale;
      }
      return {off, gain, shift};
    }
    case EffectKind::Creep: return {creep_regressor(c.ref_curve, c.dt, e.hyper)};
    case EffectKind::Channel: return {c.rec.channels[static_cast<std::size_t>(e.channel)].values};
    case EffectKind::ChannelTimesVelocity: {
      const Vec& ch = c.rec.channels[static_cast<std::size_t>(e.channel)].values;
      Vec col(n);
      for (std::size_t k = 0; k < n; ++k) col[k] = ch[k] * c.v[k];
      return {col};
    }
    case EffectKind::SensorDelay:
    case EffectKind::Backlash: break;
  }
  return {};
}

Vec effective_position(const Context& c, const Spec& s) {
  Vec x = c.rec.position;
  if (s.has_delay) x = delayed(x, c.dt, s.delay_s);
  if (s.has_backlash) x = play(x, s.backlash_width);
  return x;
}

Design build(const Context& c, const Spec& s) {
  Design d;
  d.x_eff = effective_position(c, s);
  const auto m = static_cast<std::size_t>(c.opt.elements_M);
  d.deltas.resize(m);
  calibration::thresholds(m, s.delta_max, true, c.opt.geometric_ratio, d.deltas.data());
  std::vector<Vec> nreg;
  maxwell_slip_regressors(d.x_eff, d.deltas, nreg);
  std::vector<std::vector<Vec>> extra;
  const std::size_t nc = 4 + s.knots.size();
  std::size_t p = nc + m;
  for (const auto& e : s.columns) {
    extra.push_back(column_values(c, e));
    p += extra.back().size();
  }
  d.x.resize(static_cast<Index>(c.n), static_cast<Index>(p));
  const double mid = 0.5 * (c.xmax + c.xmin);
  const double half = 0.5 * c.xrange;
  for (std::size_t k = 0; k < c.n; ++k) {
    const double sx = (d.x_eff[k] - mid) / half;
    const auto r = static_cast<Index>(k);
    d.x(r, 0) = 1.0;
    d.x(r, 1) = sx;
    d.x(r, 2) = sx * sx;
    d.x(r, 3) = sx * sx * sx;
    for (std::size_t j = 0; j < s.knots.size(); ++j) {
      const double u = std::max(0.0, sx - s.knots[j]);
      d.x(r, static_cast<Index>(4 + j)) = u * u * u;
    }
  }
  for (std::size_t j = 0; j < nc; ++j) {
    d.nonneg.push_back(false);
    d.owner.push_back(-2);
  }
  auto col = static_cast<Index>(nc);
  for (std::size_t i = 0; i < m; ++i, ++col) {
    for (std::size_t k = 0; k < c.n; ++k) d.x(static_cast<Index>(k), col) = nreg[i][k];
    d.nonneg.push_back(true);
    d.owner.push_back(-1);
  }
  for (std::size_t e = 0; e < extra.size(); ++e) {
    for (const Vec& v : extra[e]) {
      for (std::size_t k = 0; k < c.n; ++k) d.x(static_cast<Index>(k), col) = v[k];
      d.nonneg.push_back(false);
      d.owner.push_back(static_cast<int>(e));
      ++col;
    }
  }
  return d;
}

Eigen::VectorXd fit(const Context& c, const Design& d, const std::vector<Index>& rows) {
  return solve_bounded(normal_equations(d.x, c.y, rows), d.nonneg);
}

struct Evaluated {
  Design design;
  Eigen::VectorXd coef;
  Eigen::VectorXd residual;
  ErrorFigures errors;
  Vec truth_error;
};

Evaluated evaluate(const Context& c, const Spec& s, Design d, const Eigen::VectorXd& coef) {
  Evaluated ev;
  ev.coef = coef;
  ev.residual = c.y - d.x * coef;
  ErrorFigures& e = ev.errors;
  std::vector<Index> all(c.n);
  std::iota(all.begin(), all.end(), Index{0});
  e.rms_residual = rms_of(ev.residual, all);
  const std::size_t first = std::min(calibration::first_known_sample(d.x_eff.data(), c.n, s.delta_max), c.n - 1);
  e.unscored_initial_samples = first;
  e.max_residual = ev.residual.tail(static_cast<Index>(c.n - first)).cwiseAbs().maxCoeff();
  e.holdout_rms_residual = rms_of(ev.residual, c.holdout);
  if (!c.rec.truth.empty()) {
    e.has_truth = true;
    // Estimate: the reading minus the terms attributed to the sensor.
    Eigen::VectorXd sensor = Eigen::VectorXd::Zero(static_cast<Index>(c.n));
    for (Index j = 0; j < d.x.cols(); ++j) {
      const int o = d.owner[static_cast<std::size_t>(j)];
      bool is_sensor = o == -1;
      if (o >= 0) {
        const EffectKind kind = s.columns[static_cast<std::size_t>(o)].kind;
        is_sensor = c.opt.is_sensor_effect(to_string(kind));
        // Of the temperature columns only the first (load-cell offset) belongs to the sensor;
        // the curve's gain and shift with temperature are changes of the true force.
        if (kind == EffectKind::TemperatureDrift && j > 0 && d.owner[static_cast<std::size_t>(j - 1)] == o) is_sensor = false;
      }
      if (is_sensor) sensor += d.x.col(j) * coef(j);
    }
    // A sensor delay means the reading at t belongs to the true force at t - delay.
    const Vec truth = (s.has_delay && c.opt.is_sensor_effect("sensor_delay")) ? delayed(c.rec.truth, c.dt, s.delay_s)
                                                                                : c.rec.truth;
    ev.truth_error.resize(c.n);
    double ss = 0.0, mx = 0.0;
    for (std::size_t k = 0; k < c.n; ++k) {
      const double err = c.rec.force[k] - sensor(static_cast<Index>(k)) - truth[k];
      ev.truth_error[k] = err;
      if (k < first) continue;
      ss += err * err;
      mx = std::max(mx, std::abs(err));
    }
    e.rms_truth_error = std::sqrt(ss / static_cast<double>(c.n - first));
    e.max_truth_error = mx;
  }
  ev.design = std::move(d);
  return ev;
}

double search_rms(const Context& c, const Spec& s) {
  const Design d = build(c, s);
  const Eigen::VectorXd b = fit(c, d, c.train_search);
  return rms_of(c.y - d.x * b, c.train_search);
}

double choose_delta_max(const Context& c, Spec s) {
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

// Chooses the curve's knots (fewest within tolerance of the best held-out RMS) and Delta_max
// (fit-part RMS) for the model `s` otherwise as it is.
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
    const double r = rms_of(c.y - d.x * fit(c, d, c.train), c.holdout);
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

void update_refs(Context& c, const Evaluated& ev) {
  const Design& d = ev.design;
  c.ref_curve.assign(c.n, 0.0);
  c.ref_friction.assign(c.n, 0.0);
  for (Index j = 0; j < d.x.cols(); ++j) {
    const int o = d.owner[static_cast<std::size_t>(j)];
    if (o != -2 && o != -1) continue;
    Vec& target = o == -2 ? c.ref_curve : c.ref_friction;
    for (std::size_t k = 0; k < c.n; ++k) target[k] += d.x(static_cast<Index>(k), j) * ev.coef(j);
  }
  double mx = 0.0;
  for (double v : c.ref_curve) mx = std::max(mx, std::abs(v));
  c.ref_curve_scale = mx > 0.0 ? mx : 1.0;
  // Slope of the curve along the effective position (d curve / d x), for the temperature shift.
  const double half = 0.5 * c.xrange;
  c.ref_slope.assign(c.n, 0.0);
  const std::size_t nk = static_cast<std::size_t>(d.x.cols());
  for (std::size_t k = 0; k < c.n; ++k) {
    const double sx = d.x(static_cast<Index>(k), 1);
    double g = ev.coef(1) + 2.0 * ev.coef(2) * sx + 3.0 * ev.coef(3) * sx * sx;
    for (std::size_t j = 4; j < nk && d.owner[j] == -2; ++j) {
      const double u = d.x(static_cast<Index>(k), static_cast<Index>(j));  // (s - knot)_+^3
      g += 3.0 * ev.coef(static_cast<Index>(j)) * std::cbrt(u * u);
    }
    c.ref_slope[k] = g / half;
  }
  mx = 0.0;
  for (double v : c.ref_slope) mx = std::max(mx, std::abs(v));
  c.ref_slope_scale = mx > 0.0 ? mx : 1.0;
}

// Consistency of the held-out improvement: the held-out samples are cut into `blocks` contiguous
// chunks; t is the one-sample t statistic of log(MSE_old / MSE_new) over the chunks. The log ratio
// is scale-free, so chunks with large and small errors weigh alike, and a candidate that only fits
// noise improves some chunks and worsens others (mean near or below zero).
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

struct Candidate {
  EffectKind kind;
  std::string name;
  int channel = -1;
};

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

struct Scored {
  CandidateScore score;
  Spec spec;
};

// "" when the candidate's own fitted parameters are physical, else which one is not.
std::string physical_bounds_violation(const Context& c, const Spec& s, const Design& d, const Eigen::VectorXd& b,
                                      const std::string& name);

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
  out.score.holdout_rms = rms_of(r, c.holdout);
  out.score.relative_drop = 1.0 - out.score.holdout_rms / current_holdout_rms;
  out.score.t_statistic = paired_t(current_residual, r, c.holdout, c.opt.significance_blocks);
  out.score.significant =
      out.score.relative_drop >= c.opt.min_relative_drop && out.score.t_statistic >= c.opt.min_t_statistic;
  out.score.rejected_reason = physical_bounds_violation(c, out.spec, d, b, cand.name);
  if (!out.score.rejected_reason.empty()) out.score.significant = false;
  return out;
}

// Curve coefficients back in position units: p(s) with s = alpha x + beta.
std::vector<Parameter> model_parameters(const Context& c, const Spec& s, const Evaluated& ev) {
  std::vector<Parameter> out;
  const Eigen::VectorXd& b = ev.coef;
  const double al = 2.0 / c.xrange;
  const double be = -(c.xmax + c.xmin) / c.xrange;
  // A..D: the cubic part (the whole curve when there are no knots).
  out.push_back({"A", b(3) * al * al * al, "force/position^3"});
  out.push_back({"B", (b(2) + 3.0 * b(3) * be) * al * al, "force/position^2"});
  out.push_back({"C", (b(1) + 2.0 * b(2) * be + 3.0 * b(3) * be * be) * al, "force/position"});
  out.push_back({"D", b(0) + b(1) * be + b(2) * be * be + b(3) * be * be * be, "force"});
  const std::size_t nc = 4 + s.knots.size();
  for (std::size_t j = 0; j < s.knots.size(); ++j) {
    out.push_back({"knot_" + std::to_string(j + 1), (s.knots[j] - be) / al, "position"});
    out.push_back({"knot_" + std::to_string(j + 1) + "_cubic", b(static_cast<Index>(4 + j)) * al * al * al,
                   "force/position^3"});
  }
  out.push_back({"Delta_max", s.delta_max, "position"});
  double bound = 0.0;
  for (std::size_t i = 0; i < ev.design.deltas.size(); ++i) bound += b(static_cast<Index>(nc + i));
  out.push_back({"friction_bound", bound, "force"});  // sum K_i Delta_i: the Coulomb-like level
  for (std::size_t i = 0; i < ev.design.deltas.size(); ++i) {
    const double delta = ev.design.deltas[i];
    out.push_back({"K_" + std::to_string(i + 1), b(static_cast<Index>(nc + i)) / delta, "force/position"});
  }
  if (s.has_delay) out.push_back({"sensor_delay.delay_s", s.delay_s, "s"});
  if (s.has_backlash) out.push_back({"backlash.width", s.backlash_width, "position"});
  Index j = static_cast<Index>(nc + ev.design.deltas.size());
  for (const auto& e : s.columns) {
    const std::string p = e.name + ".";
    switch (e.kind) {
      case EffectKind::ViscousFriction: out.push_back({p + "coefficient", b(j++), "force/(position/s)"}); break;
      case EffectKind::Inertia: out.push_back({p + "mass", b(j++), "force/(position/s^2)"}); break;
      case EffectKind::LoadDependentFriction:
        out.push_back({p + "friction_gain_at_full_curve", b(j++), "1"});
        out.push_back({p + "reference_force", c.ref_curve_scale, "force"});  // the full curve's |force|
        break;
      case EffectKind::TemperatureDrift:
        out.push_back({p + "sensor_offset_per_degC", b(j++), "force/degC"});
        out.push_back({p + "curve_gain_per_degC", b(j++) / c.ref_curve_scale, "1/degC"});
        out.push_back({p + "curve_shift_per_degC", -b(j++) / c.ref_slope_scale, "position/degC"});
        out.push_back({p + "reference_temperature_C", c.temp_ref, "degC"});
        break;
      case EffectKind::Creep:
        out.push_back({p + "tau_s", e.hyper, "s"});
        out.push_back({p + "unrelaxed_fraction", b(j++), "1"});
        break;
      case EffectKind::Channel: out.push_back({p + "coefficient", b(j++), "force/channel"}); break;
      case EffectKind::ChannelTimesVelocity:
        out.push_back({p + "coefficient", b(j++), "force/(channel*position/s)"});
        break;
      case EffectKind::SensorDelay:
      case EffectKind::Backlash: break;
    }
  }
  return out;
}

// Offset-versus-shift split of a temperature_drift step: the correlation of the two fitted
// coefficients and the offset's standard error, from sigma^2 (X'X)^-1 over the fit rows.
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
  const LsqProblem p = normal_equations(d.x, c.y, c.train);
  const Eigen::VectorXd scale = p.gram.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd g = scale.asDiagonal() * p.gram * scale.asDiagonal();
  const Eigen::MatrixXd inv = g.ldlt().solve(Eigen::MatrixXd::Identity(g.rows(), g.cols()));
  const double corr = inv(offset_col, shift_col) / std::sqrt(inv(offset_col, offset_col) * inv(shift_col, shift_col));
  double rss = 0.0;
  for (Index k : c.train) rss += ev.residual(k) * ev.residual(k);
  const double dof = std::max(1.0, static_cast<double>(c.train.size()) - static_cast<double>(d.x.cols()));
  st.offset_shift_correlation = std::isfinite(corr) ? corr : 1.0;
  st.offset_standard_error = std::sqrt(rss / dof * inv(offset_col, offset_col)) * scale(offset_col);
  st.ambiguous = std::abs(st.offset_shift_correlation) >= AnalysisResult::kAmbiguousCorrelation;
}

std::vector<Parameter> effect_parameters(const std::vector<Parameter>& all, const std::string& name) {
  std::vector<Parameter> out;
  for (const auto& p : all)
    if (p.name.rfind(name + ".", 0) == 0) out.push_back(p);
  return out;
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

Vec display_signal(const Context& c, const Spec& s, const std::string& name) {
  if (name == "sensor_delay" || name == "viscous_friction") return c.v;
  if (name == "inertia") return c.a;
  if (name == "temperature_drift") return c.rec.temperature;
  if (name == "backlash") {
    const Vec p = play(c.rec.position, s.backlash_width);
    Vec out(c.n);
    for (std::size_t k = 0; k < c.n; ++k) out[k] = c.rec.position[k] - p[k];
    return out;
  }
  for (const auto& e : s.columns)
    if (e.name == name) return column_values(c, e).front();
  return c.rec.position;
}

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

namespace {

std::size_t reject_in(std::vector<double>& v, const std::string& name, std::vector<std::string>* where) {
  if (v.size() < 20) return 0;
  std::vector<double> sorted;
  sorted.reserve(v.size());
  for (double x : v)
    if (std::isfinite(x)) sorted.push_back(x);
  if (sorted.size() < 20) return 0;
  const auto at = [&](double q) {
    const auto i = static_cast<std::ptrdiff_t>(q * static_cast<double>(sorted.size() - 1));
    std::nth_element(sorted.begin(), sorted.begin() + i, sorted.end());
    return sorted[static_cast<std::size_t>(i)];
  };
  const double lo = at(0.005), hi = at(0.995);
  const double span = std::max(hi - lo, 1e-12 * std::max(std::abs(lo), std::abs(hi)));
  const double min_ok = lo - 10.0 * span, max_ok = hi + 10.0 * span;
  std::size_t count = 0;
  double last_good = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (v[k] >= min_ok && v[k] <= max_ok) {
      last_good = v[k];
      continue;
    }
    ++count;
    if (where && where->size() < 10) where->push_back(name + "@" + std::to_string(k));
    if (std::isfinite(last_good)) {
      v[k] = last_good;
    } else {  // at the start: the next good value
      std::size_t j = k + 1;
      while (j < v.size() && !(v[j] >= min_ok && v[j] <= max_ok)) ++j;
      v[k] = j < v.size() ? v[j] : 0.5 * (lo + hi);
    }
  }
  return count;
}

}  // namespace

std::size_t reject_gross_outliers(Recording& rec, std::vector<std::string>* where) {
  std::size_t n = reject_in(rec.position, "position", where);
  n += reject_in(rec.force, "force", where);
  n += reject_in(rec.truth, "truth", where);
  n += reject_in(rec.temperature, "temperature", where);
  n += reject_in(rec.velocity, "velocity", where);
  n += reject_in(rec.acceleration, "acceleration", where);
  for (auto& ch : rec.channels) n += reject_in(ch.values, "channel:" + ch.name, where);
  return n;
}

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

  // Structure left in the final residual.
  const Vec& r = res.residual_after;
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
    const DependenceTest t = dependence(r, by, opt.structure_bins, name);
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
