#include "bbw/analysis/design.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "bbw/analysis/bounded_lsq.hpp"
#include "bbw/analysis/effects.hpp"
#include "bbw/model/maxwell_slip.hpp"
#include "bbw/model/states_known.hpp"

namespace bbw::analysis::detail {

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
  d.first_known = calibration::first_known_sample(d.x_eff.data(), c.n, s.delta_max);
  if (c.opt.friction_thresholds.empty()) {
    d.deltas.resize(static_cast<std::size_t>(c.opt.elements_M));
    calibration::thresholds(d.deltas.size(), s.delta_max, true, c.opt.geometric_ratio, d.deltas.data());
  } else {
    d.deltas = c.opt.friction_thresholds;  // the online calibrator's element set
  }
  const std::size_t m = d.deltas.size();
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

std::vector<Index> fit_rows(const Design& d, const std::vector<Index>& rows) {
  const auto from = std::lower_bound(rows.begin(), rows.end(), static_cast<Index>(d.first_known));
  if (rows.end() - from < 2 * d.x.cols()) return rows;
  return std::vector<Index>(from, rows.end());
}

Eigen::VectorXd fit(const Context& c, const Design& d, const std::vector<Index>& rows) {
  return solve_bounded(normal_equations(d.x, c.y, fit_rows(d, rows)), d.nonneg);
}

Evaluated evaluate(const Context& c, const Spec& s, Design d, const Eigen::VectorXd& coef) {
  Evaluated ev;
  ev.coef = coef;
  ev.residual = c.y - d.x * coef;
  ErrorFigures& e = ev.errors;
  const std::size_t first = std::min(d.first_known, c.n - 1);
  std::vector<Index> scored(c.n - first);
  std::iota(scored.begin(), scored.end(), static_cast<Index>(first));
  e.rms_residual = rms_of(ev.residual, scored);
  e.unscored_initial_samples = first;
  e.max_residual = ev.residual.tail(static_cast<Index>(c.n - first)).cwiseAbs().maxCoeff();
  e.holdout_rms_residual = rms_of(ev.residual, fit_rows(d, c.holdout));
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
  const std::vector<Index> rows = fit_rows(d, c.train_search);
  const Eigen::VectorXd b = solve_bounded(normal_equations(d.x, c.y, rows), d.nonneg);
  return rms_of(c.y - d.x * b, rows);
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

std::vector<Parameter> effect_parameters(const std::vector<Parameter>& all, const std::string& name) {
  std::vector<Parameter> out;
  for (const auto& p : all)
    if (p.name.rfind(name + ".", 0) == 0) out.push_back(p);
  return out;
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

}  // namespace bbw::analysis::detail
