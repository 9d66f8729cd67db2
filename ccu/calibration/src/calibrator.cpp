#include "bbw/calibration/calibrator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "bbw/model/effect_terms.hpp"
#include "bbw/model/maxwell_slip.hpp"

namespace bbw::calibration {

namespace {

constexpr int kCurveTerms = 4;

// Solves the 4 x 4 normal equations of a cubic fit to the PF points once, at construction:
// proj (4 x (N+1)) maps PF forces to coefficients of the cubic in u = (X - xc) / xh.
std::vector<double> pf_projection(const std::vector<double>& pf_x, double xc, double xh) {
  const std::size_t n = pf_x.size();
  double g[16] = {0};
  std::vector<double> v(n * 4);
  for (std::size_t k = 0; k < n; ++k) {
    const double u = (pf_x[k] - xc) / xh;
    double p = 1.0;
    for (int m = 0; m < 4; ++m) {
      v[k * 4 + static_cast<std::size_t>(m)] = p;
      p *= u;
    }
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) g[r * 4 + c] += v[k * 4 + static_cast<std::size_t>(r)] * v[k * 4 + static_cast<std::size_t>(c)];
    }
  }
  // Invert g (SPD, 4 x 4) by Gauss-Jordan.
  double inv[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  for (int c = 0; c < 4; ++c) {
    int piv = c;
    for (int r = c + 1; r < 4; ++r) {
      if (std::fabs(g[r * 4 + c]) > std::fabs(g[piv * 4 + c])) piv = r;
    }
    for (int k = 0; k < 4; ++k) {
      std::swap(g[c * 4 + k], g[piv * 4 + k]);
      std::swap(inv[c * 4 + k], inv[piv * 4 + k]);
    }
    const double d = g[c * 4 + c];
    if (std::fabs(d) < 1e-300) throw std::invalid_argument("pf_points_N too small to fit a cubic");
    for (int k = 0; k < 4; ++k) {
      g[c * 4 + k] /= d;
      inv[c * 4 + k] /= d;
    }
    for (int r = 0; r < 4; ++r) {
      if (r == c) continue;
      const double f = g[r * 4 + c];
      for (int k = 0; k < 4; ++k) {
        g[r * 4 + k] -= f * g[c * 4 + k];
        inv[r * 4 + k] -= f * inv[c * 4 + k];
      }
    }
  }
  std::vector<double> proj(4 * n, 0.0);
  for (int r = 0; r < 4; ++r) {
    for (std::size_t k = 0; k < n; ++k) {
      double s = 0.0;
      for (int c = 0; c < 4; ++c) s += inv[r * 4 + c] * v[k * 4 + static_cast<std::size_t>(c)];
      proj[static_cast<std::size_t>(r) * n + k] = s;
    }
  }
  return proj;
}

// Cubic in u = (x - xc) / xh -> raw coefficients.
Curve raw_from_scaled(const double c[4], double xc, double xh) {
  const double s = 1.0 / xh;
  const double t = -xc / xh;
  Curve out;
  out.a = c[3] * s * s * s;
  out.b = c[2] * s * s + 3.0 * c[3] * s * s * t;
  out.c = c[1] * s + 2.0 * c[2] * s * t + 3.0 * c[3] * s * t * t;
  out.d = c[0] + c[1] * t + c[2] * t * t + c[3] * t * t * t;
  return out;
}

}  // namespace

Calibrator::Calibrator(const CalibratorConfig& config)
    : config_((config.validate(), config)),
      robust_(config.mode == Mode::Robust),
      streaming_(robust_ && config.streaming_states),
      scaled_(robust_ && config.scale_x),
      nonneg_(robust_ && config.nonnegative_k),
      m_(config.elements_M),
      e_(config.effect_columns()),
      p_(kCurveTerms + config.elements_M + e_),
      xc_rev_(0.5 * (config.x_max_rev + config.x_min_rev)),
      xh_rev_(0.5 * (config.x_max_rev - config.x_min_rev)),
      curve_(config.initial_curve),
      detector_(config.start_lag_n0, robust_ ? config.start_margin_rev : 0.0),
      store_(config.samples_L, config.elements_M + e_, config.x_max_rev - config.x_min_rev,
             config.f_max_kN - config.f_min_kN, config.drop_rule),
      states_known_rule_(config.delta_max_rev),
      position_delay_(CalibratorConfig::force_delay_slots(config.force_delay_s)),
      solver_(p_) {
  const auto m = static_cast<std::size_t>(m_);
  const auto p = static_cast<std::size_t>(p_);
  friction_.delta_rev = friction_thresholds_rev(config);
  friction_.stiffness_kN_per_rev.assign(m, 0.0);
  phi_kN_.assign(m + static_cast<std::size_t>(e_), 0.0);
  identified_.assign(m + static_cast<std::size_t>(e_), 0);

  const auto n_pf = static_cast<std::size_t>(config.pf_points_N) + 1;
  pf_x_rev_.resize(n_pf);
  pf_f_kN_.resize(n_pf);
  for (std::size_t k = 0; k < n_pf; ++k) {
    pf_x_rev_[k] = config.x_min_rev + static_cast<double>(k) * (config.x_max_rev - config.x_min_rev) /
                                          static_cast<double>(config.pf_points_N);
  }
  pf_proj_ = pf_projection(pf_x_rev_, xc_rev_, xh_rev_);
  for (std::size_t k = 0; k < n_pf; ++k) pf_f_kN_[k] = curve_.force_kN(pf_x_rev_[k]);

  element_pos_rev_.assign(m, 0.0);
  temperature_C_ = config.load_cell_offset_reference_C;
  n_now_.assign(m + static_cast<std::size_t>(e_), 0.0);
  if (e_ > 0) {
    vel_t_s_.assign(static_cast<std::size_t>(config.velocity_window), 0.0);
    vel_x_rev_.assign(static_cast<std::size_t>(config.velocity_window), 0.0);
  }
  start_pos_rev_.assign(m, 0.0);
  residual_kN_.assign(static_cast<std::size_t>(robust_ ? config.residual_window : 1), 0.0);
  gram_.assign(p * p, 0.0);
  rhs_.assign(p, 0.0);
  theta_.assign(p, 0.0);
  row_.assign(p, 0.0);
  full_row_.assign(p, 0.0);
  n_replay_.assign(m + static_cast<std::size_t>(e_), 0.0);
  pos_replay_.assign(m, 0.0);
  column_on_.assign(p, 1);
  column_map_.assign(p, 0);
  nonneg_flags_.assign(p, 0);
  if (robust_ && config.friction_memory > 0.0) {
    const std::size_t q = m + static_cast<std::size_t>(e_);
    info_kN_.assign(q * (q + 1) / 2, 0.0f);
    info_rhs_kN_.assign(q, 0.0);
  }
  if (!config.initial_stiffness_kN_per_rev.empty()) {
    set_friction_prior(config.initial_stiffness_kN_per_rev, config.initial_friction_weight,
                       config.initial_viscous_kN_per_rev_per_s);
  }
}

std::size_t Calibrator::state_bytes() const {
  auto vb = [](const auto& v) { return v.capacity() * sizeof(typename std::decay_t<decltype(v)>::value_type); };
  return sizeof(*this) + vb(friction_.delta_rev) + vb(friction_.stiffness_kN_per_rev) + vb(phi_kN_) +
         vb(pf_x_rev_) + vb(pf_f_kN_) + vb(pf_proj_) + (store_.bytes() - sizeof(store_)) +
         (solver_.bytes() - sizeof(solver_)) + vb(element_pos_rev_) + vb(n_now_) + vb(vel_t_s_) + vb(vel_x_rev_) + 2 * position_delay_.capacity() * sizeof(double) + vb(start_pos_rev_) +
         vb(gram_) + vb(rhs_) + vb(theta_) + vb(row_) + vb(full_row_) + vb(n_replay_) + vb(pos_replay_) + vb(column_on_) +
         vb(column_map_) + vb(info_kN_) + vb(info_rhs_kN_) + vb(nonneg_flags_) + vb(identified_) + vb(residual_kN_) + static_cast<std::size_t>(2 * config_.start_lag_n0 + 1) * sizeof(double);
}

void Calibrator::reset_curve(const Curve& curve) {
  curve_ = curve;
  for (std::size_t k = 0; k < pf_x_rev_.size(); ++k) pf_f_kN_[k] = curve_.force_kN(pf_x_rev_[k]);
  stats_.curve_data_min_rev = 1.0;  // no fit's data behind it
  stats_.curve_data_max_rev = 0.0;
}

void Calibrator::set_friction_stiffness(const std::vector<double>& k_kN_per_rev, bool from_fits) {
  if (k_kN_per_rev.size() != friction_.delta_rev.size()) {
    throw std::invalid_argument("set_friction_stiffness: expected " + std::to_string(friction_.delta_rev.size()) +
                                " stiffnesses, got " + std::to_string(k_kN_per_rev.size()));
  }
  for (std::size_t i = 0; i < k_kN_per_rev.size(); ++i) {
    friction_.stiffness_kN_per_rev[i] = k_kN_per_rev[i];
    phi_kN_[i] = k_kN_per_rev[i] * friction_.delta_rev[i];
  }
  prior_friction_fitted_ = from_fits;
}

void Calibrator::set_friction_prior(const std::vector<double>& k_kN_per_rev, double weight,
                                    double viscous_kN_per_rev_per_s) {
  if (!(weight >= 0.0) || !std::isfinite(weight)) {
    throw std::invalid_argument("set_friction_prior: weight must be finite and >= 0, got " + std::to_string(weight));
  }
  if (!(viscous_kN_per_rev_per_s >= 0.0) || !std::isfinite(viscous_kN_per_rev_per_s)) {
    throw std::invalid_argument("set_friction_prior: viscous coefficient must be finite and >= 0, got " +
                                std::to_string(viscous_kN_per_rev_per_s));
  }
  set_friction_stiffness(k_kN_per_rev, true);
  // The viscous column is the first after the elements (effect_columns).
  const auto viscous = static_cast<std::size_t>(m_);
  if (config_.viscous_friction) {
    phi_kN_[viscous] = viscous_kN_per_rev_per_s * config_.viscous_speed_scale_rev_per_s;
    friction_.viscous_kN_per_rev_per_s = viscous_kN_per_rev_per_s;
  }
  if (info_rhs_kN_.empty()) return;  // no friction memory: no prior to hold
  const std::size_t q = info_rhs_kN_.size();
  std::fill(info_kN_.begin(), info_kN_.end(), 0.0f);
  std::fill(info_rhs_kN_.begin(), info_rhs_kN_.end(), 0.0);
  for (std::size_t a = 0, t = 0; a < q; t += q - a, ++a) {
    // The elements and the viscous term (the other effect columns keep none).
    if (a > viscous || (a == viscous && !config_.viscous_friction)) break;
    info_kN_[t] = static_cast<float>(weight);  // (a, a): the first of row a's upper triangle
    info_rhs_kN_[a] = weight * phi_kN_[a];
  }
}

double Calibrator::poly_basis_x(double x_rev, int power) const {
  const double u = scaled_ ? (x_rev - xc_rev_) / xh_rev_ : x_rev;
  double v = 1.0;
  for (int k = 0; k < power; ++k) v *= u;
  return v;
}

// Row of the eq. 5 regression. Robust: [1, u, u^2, u^3, n_1..n_M] (parameters: the cubic
// deviation from the current curve in u, and phi_i = K_i Delta_i). Paper: [1, x, x^2, x^3,
// Delta_i n_i] (parameters D, C, B, A, K_i).
void Calibrator::regressor_row(double x_rev, const double* n, double* row) const {
  const double u = scaled_ ? (x_rev - xc_rev_) / xh_rev_ : x_rev;
  row[0] = 1.0;
  row[1] = u;
  row[2] = u * u;
  row[3] = u * u * u;
  for (int i = 0; i < m_; ++i) {
    row[kCurveTerms + i] = robust_ ? n[i] : friction_.delta_rev[static_cast<std::size_t>(i)] * n[i];
  }
  for (int i = 0; i < e_; ++i) row[kCurveTerms + m_ + i] = n[m_ + i];
}

void Calibrator::start_cycle(double x_rev) {
  store_.clear();
  in_cycle_ = true;
  samples_since_start_ = 0;
  ++stats_.cycles_detected;
  for (int i = 0; i < m_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    // At a start all elements were slipping downwards: x0_i = x(start) + Delta_i.
    start_pos_rev_[k] = x_rev + friction_.delta_rev[k];
    if (!streaming_) element_pos_rev_[k] = start_pos_rev_[k];
  }
}

// Calls f(row, b) for each stored sample in time order: `row` holds the regressors of the
// columns taking part (column_map_), `b` the target. Paper mode (no streaming states) replays
// the elements from x0_i over the stored samples, as the flowchart does. Robust mode's target
// is the deviation from the current curve minus the friction of the elements kept fixed.
template <class F>
void Calibrator::for_each_fit_row(std::size_t columns, F&& f) {
  for (int i = 0; i < m_; ++i) pos_replay_[static_cast<std::size_t>(i)] = start_pos_rev_[static_cast<std::size_t>(i)];
  double* full = full_row_.data();
  double* row = row_.data();
  for (std::size_t r = 0; r < store_.size(); ++r) {
    const double x = store_.x_rev(r);
    const float* stored = store_.n_row(r);
    double* n = n_replay_.data();
    if (streaming_) {
      for (int i = 0; i < m_ + e_; ++i) n[i] = stored[i];
    } else {
      elements_step(x, friction_.delta_rev.data(), pos_replay_.data(), static_cast<std::size_t>(m_), nullptr, n);
      const double scale = load_scale(x);
      for (int i = 0; i < m_; ++i) n[i] *= scale;
      for (int i = 0; i < e_; ++i) n[m_ + i] = stored[m_ + i];
    }
    regressor_row(x, n, full);
    double b = store_.f_kN(r);
    if (robust_) {
      b -= curve_.force_kN(x);
      for (int i = 0; i < m_; ++i) {
        if (!column_on_[static_cast<std::size_t>(kCurveTerms + i)]) b -= phi_kN_[static_cast<std::size_t>(i)] * n[i];
      }
    }
    for (std::size_t a = 0; a < columns; ++a) row[a] = full[column_map_[a]];
    f(row, b);
  }
}

bool Calibrator::end_cycle() {
  if (robust_ && config_.friction_memory > 0.0) return end_cycle_with_memory();
  const std::size_t rows = store_.size();
  const double x_lo = store_.min_x_rev();
  const double x_hi = store_.max_x_rev();
  const double span = x_hi - x_lo;
  stats_.last_fit_span_rev = span;

  // Which columns take part: curve terms always; element i only when the cycle swept it
  // through both of its slip states (span >= 2 Delta_i), else it keeps its previous value.
  int p_on = 0;
  for (int j = 0; j < p_; ++j) {
    bool on = true;
    if (j >= kCurveTerms && j < kCurveTerms + m_ && robust_ && config_.identify_per_element) {
      const auto i = static_cast<std::size_t>(j - kCurveTerms);
      // An element never identified yet is fitted provisionally from a narrower cycle (its
      // partial ramps still carry its stiffness) rather than left at zero.
      on = span >= 2.0 * friction_.delta_rev[i] || !identified_[i];
    }
    column_on_[static_cast<std::size_t>(j)] = on ? 1 : 0;
    if (on) {
      column_map_[static_cast<std::size_t>(p_on)] = j;
      nonneg_flags_[static_cast<std::size_t>(p_on)] = ((nonneg_ || j >= kCurveTerms + m_) && j >= kCurveTerms) ? 1 : 0;
      ++p_on;
    }
  }
  if (rows < static_cast<std::size_t>(p_on) + 2) return false;

  const auto pu = static_cast<std::size_t>(p_on);
  std::fill(gram_.begin(), gram_.end(), 0.0);
  std::fill(rhs_.begin(), rhs_.end(), 0.0);
  for_each_fit_row(pu, [&](const double* row, double b) {
    for (std::size_t a = 0; a < pu; ++a) {
      rhs_[a] += row[a] * b;
      for (std::size_t c = a; c < pu; ++c) gram_[a * pu + c] += row[a] * row[c];
    }
  });
  for (std::size_t a = 0; a < pu; ++a) {
    for (std::size_t c = 0; c < a; ++c) gram_[a * pu + c] = gram_[c * pu + a];
  }
  bool ok;
  if (robust_) {
    const double lambda = config_.ridge * static_cast<double>(rows);
    for (std::size_t a = 0; a < pu; ++a) gram_[a * pu + a] += lambda;
    ok = solver_.solve(gram_.data(), rhs_.data(), nonneg_flags_.data(), p_on, theta_.data());
  } else {
    ok = solver_.solve_unbounded(gram_.data(), rhs_.data(), p_on, theta_.data());
  }
  if (!ok) return false;
  for (std::size_t a = 0; a < pu; ++a) {
    if (!std::isfinite(theta_[a])) return false;
  }

  // Residual RMS of the fit, recomputed row by row (|b|^2 - 2 t'h + t'G t cancels badly).
  double sse = 0.0;
  for_each_fit_row(pu, [&](const double* row, double b) {
    double model = 0.0;
    for (std::size_t a = 0; a < pu; ++a) model += row[a] * theta_[a];
    sse += (b - model) * (b - model);
  });
  const double rms = std::sqrt(sse / static_cast<double>(rows));
  stats_.last_fit_rms_kN = rms;
  if (robust_ && rms > config_.max_fit_rms_kN) return false;

  // Curve terms (first four of theta, always on).
  const double c0 = theta_[0], c1 = theta_[1], c2 = theta_[2], c3 = theta_[3];
  const bool update_curve = !robust_ || span >= config_.min_cycle_span_rev;
  if (update_curve) {
    // Robust mode also updates a PF point within half a PF spacing outside the cycle's span:
    // a start is detected a little after the turning point, so the range ends would otherwise
    // never be refreshed.
    const double margin = robust_ ? 0.5 * (config_.x_max_rev - config_.x_min_rev) / config_.pf_points_N : 0.0;
    for (std::size_t k = 0; k < pf_x_rev_.size(); ++k) {
      const double X = pf_x_rev_[k];
      if (X < x_lo - margin || X > x_hi + margin) continue;
      const double u = scaled_ ? (X - xc_rev_) / xh_rev_ : X;
      const double local = ((c3 * u + c2) * u + c1) * u + c0;
      pf_f_kN_[k] = robust_ ? curve_.force_kN(X) + local : local;
    }
    note_curve_data(x_lo, x_hi);
    refit_curve_from_pf();
  }
  // Friction amplitudes.
  for (std::size_t a = kCurveTerms; a < pu; ++a) {
    const auto i = static_cast<std::size_t>(column_map_[a] - kCurveTerms);
    const bool element = i < static_cast<std::size_t>(m_);
    const double phi_new = (robust_ || !element) ? theta_[a] : theta_[a] * friction_.delta_rev[i];
    // Smoothing starts with an element's second identification: the first replaces the
    // zero it started from (a wide friction's large elements are identified cycles later).
    // Running mean over an element's first identifications, then the exponential smoothing.
    const double w = (robust_ && identified_[i]) ? std::max(config_.k_smoothing, 1.0 / (1.0 + identified_[i])) : 1.0;
    phi_kN_[i] = (1.0 - w) * phi_kN_[i] + w * phi_new;
    if (!element || !robust_ || !config_.identify_per_element || span >= 2.0 * friction_.delta_rev[i]) {
      if (identified_[i] < 100) ++identified_[i];
    }
    if (element) friction_.stiffness_kN_per_rev[i] = phi_kN_[i] / friction_.delta_rev[i];
    else friction_.viscous_kN_per_rev_per_s = phi_kN_[i] / config_.viscous_speed_scale_rev_per_s;
  }
  return true;
}

// Friction memory (config friction_memory): every column takes part; the cycle's curve
// deviation (4 free columns) is eliminated from its normal equations, leaving the information
// S = G_ee - G_ec G_cc^-1 G_ce and r = h_e - G_ec G_cc^-1 h_c the cycle carries on the
// amplitudes (any cubic in the target, such as the change of the current curve, drops out).
// The amplitudes solve (memory * S_past + S + priors) phi = memory * r_past + r, phi >= 0;
// the curve deviation is then G_cc^-1 (h_c - G_ce phi).
bool Calibrator::end_cycle_with_memory() {
  const std::size_t rows = store_.size();
  const double x_lo = store_.min_x_rev();
  const double x_hi = store_.max_x_rev();
  const double span = x_hi - x_lo;
  stats_.last_fit_span_rev = span;
  const auto p = static_cast<std::size_t>(p_);
  const std::size_t q = p - kCurveTerms;  // amplitudes: elements, then effect columns
  for (std::size_t j = 0; j < p; ++j) {
    column_on_[j] = 1;
    column_map_[j] = static_cast<int>(j);
    nonneg_flags_[j] = (j >= kCurveTerms && (nonneg_ || j >= kCurveTerms + static_cast<std::size_t>(m_))) ? 1 : 0;
  }
  if (rows < p + 2) return false;
  std::fill(gram_.begin(), gram_.end(), 0.0);
  std::fill(rhs_.begin(), rhs_.end(), 0.0);
  for_each_fit_row(p, [&](const double* row, double b) {
    for (std::size_t a = 0; a < p; ++a) {
      rhs_[a] += row[a] * b;
      for (std::size_t c = a; c < p; ++c) gram_[a * p + c] += row[a] * row[c];
    }
  });
  for (std::size_t a = 0; a < p; ++a) {
    for (std::size_t c = 0; c < a; ++c) gram_[a * p + c] = gram_[c * p + a];
  }
  const double lambda = config_.ridge * static_cast<double>(rows);
  // G_cc^-1 (4 x 4, with the ridge) by Gauss-Jordan, and h_c, kept for the curve.
  double gcc[16], inv[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) gcc[r * 4 + c] = gram_[static_cast<std::size_t>(r) * p + static_cast<std::size_t>(c)] + (r == c ? lambda : 0.0);
  }
  for (int c = 0; c < 4; ++c) {
    const double d = gcc[c * 4 + c];
    if (!(d > 0.0) || !std::isfinite(d)) return false;
    for (int k = 0; k < 4; ++k) {
      gcc[c * 4 + k] /= d;
      inv[c * 4 + k] /= d;
    }
    for (int r = 0; r < 4; ++r) {
      if (r == c) continue;
      const double f = gcc[r * 4 + c];
      for (int k = 0; k < 4; ++k) {
        gcc[r * 4 + k] -= f * gcc[c * 4 + k];
        inv[r * 4 + k] -= f * inv[c * 4 + k];
      }
    }
  }
  double hc[4];
  for (std::size_t r = 0; r < 4; ++r) hc[r] = rhs_[r];
  // This cycle's information, in place over G_ee (upper triangle; G_ec, columns 0..3, is
  // read and not written): S_ab = G_ee,ab - G_ec,a. G_cc^-1 G_ce,.b, and r_b likewise. Then the
  // past information times the memory is added, and the ridge, and the lower triangle filled.
  double* const s_block = gram_.data() + kCurveTerms * p + kCurveTerms;  // leading dimension p
  double* const r_block = rhs_.data() + kCurveTerms;
  const double mem = config_.friction_memory;
  for (std::size_t b = 0; b < q; ++b) {
    const double* g_b = gram_.data() + (kCurveTerms + b) * p;
    double w[4];
    for (std::size_t r = 0; r < 4; ++r) w[r] = inv[r * 4 + 0] * g_b[0] + inv[r * 4 + 1] * g_b[1] + inv[r * 4 + 2] * g_b[2] + inv[r * 4 + 3] * g_b[3];
    for (std::size_t a = 0; a <= b; ++a) {
      const double* g_a = gram_.data() + (kCurveTerms + a) * p;
      s_block[a * p + b] -= g_a[0] * w[0] + g_a[1] * w[1] + g_a[2] * w[2] + g_a[3] * w[3];
    }
    r_block[b] -= w[0] * hc[0] + w[1] * hc[1] + w[2] * hc[2] + w[3] * hc[3];
  }
  std::size_t t = 0;
  for (std::size_t a = 0; a < q; ++a) {
    for (std::size_t b = a; b < q; ++b, ++t) s_block[a * p + b] += mem * static_cast<double>(info_kN_[t]);
    r_block[a] += mem * info_rhs_kN_[a];
    for (std::size_t b = 0; b < a; ++b) s_block[a * p + b] = s_block[b * p + a];
    s_block[a * p + a] += lambda;
  }
  if (!solver_.solve(s_block, r_block, nonneg_flags_.data() + kCurveTerms, static_cast<int>(q), theta_.data() + kCurveTerms,
                     static_cast<int>(p))) {
    return false;
  }
  for (std::size_t a = kCurveTerms; a < p; ++a) {
    if (!std::isfinite(theta_[a])) return false;
  }
  // The cycle's curve deviation given the amplitudes: G_cc^-1 (h_c - G_ce phi), G_ce phi summed
  // over the rows.
  double gce_phi[4] = {0, 0, 0, 0};
  for_each_fit_row(p, [&](const double* row, double) {
    double fr = 0.0;
    for (std::size_t a = kCurveTerms; a < p; ++a) fr += row[a] * theta_[a];
    for (std::size_t k = 0; k < 4; ++k) gce_phi[k] += row[k] * fr;
  });
  for (std::size_t r = 0; r < 4; ++r) {
    double v = 0.0;
    for (std::size_t k = 0; k < 4; ++k) v += inv[r * 4 + k] * (hc[k] - gce_phi[k]);
    theta_[r] = v;
  }
  double sse = 0.0;
  for_each_fit_row(p, [&](const double* row, double b) {
    double model = 0.0;
    for (std::size_t a = 0; a < p; ++a) model += row[a] * theta_[a];
    sse += (b - model) * (b - model);
  });
  const double rms = std::sqrt(sse / static_cast<double>(rows));
  stats_.last_fit_rms_kN = rms;
  if (rms > config_.max_fit_rms_kN) return false;

  // Accepted: keep the summed information (without the ridge), the amplitudes and the curve.
  t = 0;
  for (std::size_t a = 0; a < q; ++a) {
    for (std::size_t b = a; b < q; ++b, ++t) info_kN_[t] = static_cast<float>(s_block[a * p + b] - (a == b ? lambda : 0.0));
    info_rhs_kN_[a] = r_block[a];
  }
  if (span >= config_.min_cycle_span_rev) {
    const double margin = 0.5 * (config_.x_max_rev - config_.x_min_rev) / config_.pf_points_N;
    for (std::size_t k = 0; k < pf_x_rev_.size(); ++k) {
      const double X = pf_x_rev_[k];
      if (X < x_lo - margin || X > x_hi + margin) continue;
      const double u = scaled_ ? (X - xc_rev_) / xh_rev_ : X;
      pf_f_kN_[k] = curve_.force_kN(X) + ((theta_[3] * u + theta_[2]) * u + theta_[1]) * u + theta_[0];
    }
    note_curve_data(x_lo, x_hi);
    refit_curve_from_pf();
  }
  for (std::size_t i = 0; i < q; ++i) {
    phi_kN_[i] = theta_[kCurveTerms + i];
    if (i < static_cast<std::size_t>(m_)) friction_.stiffness_kN_per_rev[i] = phi_kN_[i] / friction_.delta_rev[i];
    else friction_.viscous_kN_per_rev_per_s = phi_kN_[i] / config_.viscous_speed_scale_rev_per_s;
  }
  return true;
}

void Calibrator::refit_curve_from_pf() {
  const std::size_t n = pf_x_rev_.size();
  double c[4];
  for (std::size_t r = 0; r < 4; ++r) {
    double s = 0.0;
    for (std::size_t k = 0; k < n; ++k) s += pf_proj_[r * n + k] * pf_f_kN_[k];
    c[r] = s;
  }
  curve_ = raw_from_scaled(c, xc_rev_, xh_rev_);
}

double Calibrator::load_scale(double x_rev) const {
  if (!LoadFrictionTerm::on(config_.load_friction_gain)) return 1.0;
  return LoadFrictionTerm::scale(config_.load_friction_gain, config_.load_friction_reference_kN, curve_.force_kN(x_rev));
}

// Resolver speed when the sample carries one; else the least-squares slope of the last
// velocity_window positions (causal: it lags by about half the window).
double Calibrator::speed_now(const Sample& s) {
  const std::size_t w = vel_t_s_.size();
  vel_head_ = (vel_head_ + 1) % w;
  vel_t_s_[vel_head_] = s.time_s;
  vel_x_rev_[vel_head_] = s.position_rev;
  if (vel_count_ < w) ++vel_count_;
  if (std::isfinite(s.speed_rev_per_s)) return s.speed_rev_per_s;
  if (vel_count_ < 2) return 0.0;
  double tm = 0.0, xm = 0.0;
  for (std::size_t k = 0; k < vel_count_; ++k) {
    const std::size_t i = (vel_head_ + w - k) % w;
    tm += vel_t_s_[i];
    xm += vel_x_rev_[i];
  }
  tm /= static_cast<double>(vel_count_);
  xm /= static_cast<double>(vel_count_);
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < vel_count_; ++k) {
    const std::size_t i = (vel_head_ + w - k) % w;
    num += (vel_t_s_[i] - tm) * (vel_x_rev_[i] - xm);
    den += (vel_t_s_[i] - tm) * (vel_t_s_[i] - tm);
  }
  return den > 0.0 ? num / den : 0.0;
}

Estimate Calibrator::update(const Sample& s) {
  Estimate e;
  ++stats_.samples_seen;
  const bool finite = std::isfinite(s.time_s) && std::isfinite(s.position_rev) && std::isfinite(s.force_kN);
  const bool in_range = finite && s.position_rev >= config_.accept_position_min_rev &&
                        s.position_rev <= config_.accept_position_max_rev &&
                        s.force_kN >= config_.accept_force_min_kN && s.force_kN <= config_.accept_force_max_kN;
  const bool time_ok = finite && (!have_time_ || s.time_s > last_time_s_);
  if (!in_range || !time_ok) {
    ++stats_.samples_rejected;
    e.valid = false;
    e.calibrated = stats_.fits_accepted > 0;
    e.friction_fitted = states_known_ && (e.calibrated || prior_friction_fitted_);
    return e;
  }
  // The load cell's thermal offset removed first: the model never sees it.
  double f_c = s.force_kN;
  if (LoadCellOffsetTerm::on(config_.load_cell_offset_kN_per_C)) {
    if (std::isfinite(s.temperature_C)) temperature_C_ = s.temperature_C;
    f_c -= LoadCellOffsetTerm::offset_kN(config_.load_cell_offset_kN_per_C, config_.load_cell_offset_reference_C,
                                         temperature_C_);
  }
  // With a force delay d the load cell at t belongs to the position at t - d: the model runs
  // on that position and the estimate is carried to the present along the curve.
  const bool delayed = ForceDelayTerm::on(config_.force_delay_s);
  if (delayed) position_delay_.push(s.time_s, s.position_rev);
  double x = delayed ? position_delay_.read(s.time_s - config_.force_delay_s) : s.position_rev;
  // The position the clamp force belongs to now (the curve estimate's argument).
  double x_now = s.position_rev;
  if (BacklashTerm::on(config_.backlash_width_rev)) {
    // The model runs on the spindle position; with a delay too, the play acts on the delayed
    // position and the present spindle is the play state pulled along to the present position.
    if (!have_time_) spindle_rev_ = x;
    x = BacklashTerm::spindle_rev(spindle_rev_, x, config_.backlash_width_rev);
    double pulled = spindle_rev_;
    x_now = delayed ? BacklashTerm::spindle_rev(pulled, s.position_rev, config_.backlash_width_rev) : x;
  }
  if (!have_time_) {
    for (auto& p : element_pos_rev_) p = x;
  }
  last_time_s_ = s.time_s;
  have_time_ = true;
  // The recording may start with the friction deflected either way (StatesKnown).
  if (!states_known_) states_known_ = !streaming_ || states_known_rule_.update(x);

  const bool start = detector_.update(x) && states_known_;
  if (start && (!in_cycle_ || samples_since_start_ >= static_cast<std::uint64_t>(config_.samples_L))) {
    if (in_cycle_ && fits_held_) {
      ++stats_.fits_held;
    } else if (in_cycle_) {
      if (end_cycle()) {
        ++stats_.fits_accepted;
        if (stats_.first_fit_time_s < 0.0) stats_.first_fit_time_s = s.time_s;
        e.fit_accepted = true;
      } else {
        ++stats_.fits_rejected;
      }
    }
    start_cycle(x);
    e.cycle_start = true;
  }

  // Live element states and the friction estimate for this sample.
  const double friction = elements_step(x, friction_.delta_rev.data(), element_pos_rev_.data(),
                                        static_cast<std::size_t>(m_), nullptr, n_now_.data());
  (void)friction;
  if (LoadFrictionTerm::on(config_.load_friction_gain)) {
    const double scale = load_scale(x);
    for (int i = 0; i < m_; ++i) n_now_[static_cast<std::size_t>(i)] *= scale;
  }
  if (e_ > 0) {
    // Delayed: the speed is the slope of the delayed positions (the sample's speed is current).
    const Sample at_x{s.time_s, x, f_c, delayed ? std::numeric_limits<double>::quiet_NaN() : s.speed_rev_per_s};
    n_now_[static_cast<std::size_t>(m_)] = speed_now(at_x) / config_.viscous_speed_scale_rev_per_s;
  }
  double f_fric = 0.0;
  for (int i = 0; i < m_ + e_; ++i) f_fric += phi_kN_[static_cast<std::size_t>(i)] * n_now_[static_cast<std::size_t>(i)];

  if (in_cycle_) {
    // Robust mode fits only samples inside the curve's range [x_min, x_max]: below it the pads
    // open and the cubic cannot follow the contact kink, and the large elements' partial
    // ramps would absorb that misfit as friction. The element states still run everywhere.
    if (!robust_ || (x >= config_.x_min_rev && x <= config_.x_max_rev)) store_.add(x, f_c, n_now_.data());
    ++samples_since_start_;
  }

  e.valid = true;
  e.friction_kN = f_fric;
  // (The viscous column is the first after the elements: effect_columns.)
  e.viscous_kN = config_.viscous_friction ? phi_kN_[static_cast<std::size_t>(m_)] * n_now_[static_cast<std::size_t>(m_)] : 0.0;
  e.curve_force_kN = curve_.force_kN(x_now);
  e.force_kN = f_c - f_fric;
  if (delayed) e.force_kN += e.curve_force_kN - curve_.force_kN(x);
  if (residual_kN_.size() > 1) {
    // f_hat = C(x_now) + mean of the last residuals; a new curve restarts the mean (the stored
    // residuals were taken against the old one). Outside the curve's range the residuals are not
    // carried along its cubic, whose extrapolation is steep there: residuals four samples back,
    // carried by it, were 27 kN off in a 12 rev/s release (stiff10_ff run 12, RR); along its tangent
    // 10 kN. Below the range they are carried flat (the pads open, the clamp force flattens out:
    // the error is at most its change over the window), above it along the tangent at the end (the
    // clamp force keeps rising; the cubic need not).
    if (e.fit_accepted) residual_count_ = 0;
    const double carried_kN = carrying_curve_kN(x_now);
    const std::size_t w = residual_kN_.size();
    residual_head_ = (residual_head_ + 1) % w;
    residual_kN_[residual_head_] = e.force_kN - carried_kN;
    if (residual_count_ < w) ++residual_count_;
    double sum = 0.0;
    for (std::size_t k = 0; k < residual_count_; ++k) sum += residual_kN_[(residual_head_ + w - k) % w];
    e.force_kN = carried_kN + sum / static_cast<double>(residual_count_);
  }
  e.calibrated = stats_.fits_accepted > 0;
  e.friction_fitted = states_known_ && (e.calibrated || prior_friction_fitted_);
  return e;
}

double Calibrator::carrying_curve_kN(double x_rev) const {
  const double lo = config_.x_min_rev, hi = config_.x_max_rev;
  if (x_rev < lo) return curve_.force_kN(lo);
  if (x_rev <= hi) return curve_.force_kN(x_rev);
  const Curve& c = curve_;
  const double slope = (3.0 * c.a * hi + 2.0 * c.b) * hi + c.c;
  return c.force_kN(hi) + slope * (x_rev - hi);
}

void Calibrator::note_curve_data(double x_lo_rev, double x_hi_rev) {
  const double lo = std::max(x_lo_rev, config_.x_min_rev), hi = std::min(x_hi_rev, config_.x_max_rev);
  if (!(hi >= lo)) return;
  const bool none = !(stats_.curve_data_max_rev >= stats_.curve_data_min_rev);
  stats_.curve_data_min_rev = none ? lo : std::min(stats_.curve_data_min_rev, lo);
  stats_.curve_data_max_rev = none ? hi : std::max(stats_.curve_data_max_rev, hi);
}

}  // namespace bbw::calibration
