#include "bbw/vehicle/tyre.hpp"

#include <algorithm>
#include <cmath>

namespace bbw::vehicle {

namespace {

double magic(double B, double C, double D, double E, double x) {
  const double bx = B * x;
  return D * std::sin(C * std::atan(bx - E * (bx - std::atan(bx))));
}

// d/dx of magic() (for the wheel's implicit step).
double magic_slope(double B, double C, double D, double E, double x) {
  const double bx = B * x;
  const double u = bx - E * (bx - std::atan(bx));
  const double du = B * (1.0 - E) + E * B / (1.0 + bx * bx);
  return D * std::cos(C * std::atan(u)) * C * du / (1.0 + u * u);
}

struct Longitudinal {
  double B, C, D, E;
};

Longitudinal longitudinal_terms(const TyreParams& p, double load_N, double kappa, double mu_scale, double stiffness_scale) {
  const double fz0 = p.nominal_load_N;
  const double dfz = (load_N - fz0) / fz0;
  const double C = p.pcx1;
  const double D = (p.pdx1 + p.pdx2 * dfz) * mu_scale * load_N;
  double E = (p.pex1 + p.pex2 * dfz + p.pex3 * dfz * dfz);
  E = std::min(E, 1.0);
  (void)kappa;
  const double K = load_N * (p.pkx1 + p.pkx2 * dfz) * std::exp(p.pkx3 * dfz) * stiffness_scale;
  const double B = D > 0.0 ? K / (C * D) : 0.0;
  return {B, C, D, E};
}

}  // namespace

double longitudinal_mu(const TyreParams& p, double load_N, double kappa, double mu_scale, double stiffness_scale) {
  if (load_N <= 0.0) return 0.0;
  const Longitudinal l = longitudinal_terms(p, load_N, kappa, mu_scale, stiffness_scale);
  return std::abs(magic(l.B, l.C, l.D, l.E, std::abs(kappa))) / load_N;
}

TyreForce tyre_force(const TyreParams& p, double load_N, double kappa, double alpha_rad, double mu_scale,
                     double stiffness_scale) {
  TyreForce f;
  if (load_N <= 0.0) return f;
  const double fz0 = p.nominal_load_N;
  const double dfz = (load_N - fz0) / fz0;
  // Pure longitudinal.
  const Longitudinal l = longitudinal_terms(p, load_N, kappa, mu_scale, stiffness_scale);
  const double fx0 = magic(l.B, l.C, l.D, l.E, kappa);
  const double dfx0 = magic_slope(l.B, l.C, l.D, l.E, kappa);
  // Pure lateral (force opposes the slip angle).
  const double Cy = p.pcy1;
  const double Dy = (p.pdy1 + p.pdy2 * dfz) * mu_scale * load_N;
  const double Ey = std::min(p.pey1, 1.0);
  const double Ky = p.pky1 * fz0 * std::sin(2.0 * std::atan(load_N / (p.pky2 * fz0))) * stiffness_scale;
  const double By = Dy > 0.0 ? Ky / (Cy * Dy) : 0.0;
  const double fy0 = -magic(By, Cy, Dy, Ey, alpha_rad);
  // Combined slip: G_xa weights Fx by the slip angle, G_yk weights Fy by the slip ratio.
  const double a = std::abs(alpha_rad);
  const double Bxa = p.rbx1 * std::cos(std::atan(p.rbx2 * kappa));
  const double gxa = std::cos(p.rcx1 * std::atan(Bxa * a - p.rex1 * (Bxa * a - std::atan(Bxa * a))));
  const double k = std::abs(kappa);
  const double Byk = p.rby1 * std::cos(std::atan(p.rby2 * a));
  const double gyk = std::cos(p.rcy1 * std::atan(Byk * k - p.rey1 * (Byk * k - std::atan(Byk * k))));
  f.longitudinal_N = fx0 * gxa;
  f.lateral_N = fy0 * gyk;
  f.dFx_dkappa_N = dfx0 * gxa;
  return f;
}

PeakMu peak_longitudinal_mu(const TyreParams& p, double load_N, double mu_scale, double stiffness_scale) {
  PeakMu best;
  // Coarse scan, then golden-section refinement around the best sample.
  for (int i = 1; i <= 400; ++i) {
    const double s = 0.0025 * i;
    const double m = longitudinal_mu(p, load_N, s, mu_scale, stiffness_scale);
    if (m > best.mu) best = {m, s};
  }
  double lo = std::max(0.0, best.slip - 0.0025), hi = best.slip + 0.0025;
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int i = 0; i < 60; ++i) {
    const double a = hi - g * (hi - lo), b = lo + g * (hi - lo);
    if (longitudinal_mu(p, load_N, a, mu_scale, stiffness_scale) > longitudinal_mu(p, load_N, b, mu_scale, stiffness_scale)) {
      hi = b;
    } else {
      lo = a;
    }
  }
  const double s = 0.5 * (lo + hi);
  const double m = longitudinal_mu(p, load_N, s, mu_scale, stiffness_scale);
  if (m > best.mu) best = {m, s};
  return best;
}

double sliding_mu(const TyreParams& p, double load_N, double mu_scale, double stiffness_scale) {
  return longitudinal_mu(p, load_N, 1.0, mu_scale, stiffness_scale);
}

}  // namespace bbw::vehicle
