// The Magic Formula tyre (Pacejka 2002 without shift terms): pure longitudinal and lateral slip
// with load dependence, and combined slip by the weighting functions G_xa, G_yk. Pure arithmetic.
#pragma once

#include "bbw/vehicle/params.hpp"

namespace bbw::vehicle {

struct TyreForce {
  double longitudinal_N = 0.0;  // along the wheel's heading; negative brakes
  double lateral_N = 0.0;       // to the wheel's left
  double dFx_dkappa_N = 0.0;    // slope of the longitudinal force in slip (for the implicit wheel step)
};

// kappa: longitudinal slip (R omega - v_x) / |v_x| (negative braking); alpha_rad: slip angle,
// atan(v_y / |v_x|) of the contact patch's velocity (positive: it moves to the left, the force
// points right). mu_scale, stiffness_scale: the surface's (LMUX = LMUY, LKX = LKY).
TyreForce tyre_force(const TyreParams& p, double load_N, double kappa, double alpha_rad, double mu_scale,
                     double stiffness_scale);

// Pure longitudinal force coefficient Fx / Fz at slip kappa (magnitude, kappa >= 0 braking sense).
double longitudinal_mu(const TyreParams& p, double load_N, double kappa, double mu_scale, double stiffness_scale);

struct PeakMu {
  double mu = 0.0;     // max over slip of |Fx| / Fz
  double slip = 0.0;   // where (|kappa|)
};
// The pure-slip longitudinal peak and the sliding (kappa = -1) coefficient at a load.
PeakMu peak_longitudinal_mu(const TyreParams& p, double load_N, double mu_scale, double stiffness_scale);
double sliding_mu(const TyreParams& p, double load_N, double mu_scale, double stiffness_scale);

}  // namespace bbw::vehicle
