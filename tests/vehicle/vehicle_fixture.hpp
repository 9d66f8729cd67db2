// Shared set-up for the vehicle plant tests: the shipped parameters (config/vehicle/sedan.yaml's
// defaults in code) and a uniform road.
#pragma once

#include "bbw/vehicle/params.hpp"
#include "bbw/vehicle/vehicle.hpp"

namespace bbw::test {

inline vehicle::RoadParams uniform_road(double mu_scale, double stiffness_scale) {
  vehicle::RoadParams r;
  r.surfaces = {{"test", mu_scale, stiffness_scale}};
  r.ambient_C = 20.0;
  return r;
}

// No drag, no rolling resistance, and a tyre whose coefficients do not depend on load: the
// closed forms of a point mass apply.
inline vehicle::VehicleParams load_independent() {
  vehicle::VehicleParams p;
  p.tyre.pdx2 = p.tyre.pex2 = p.tyre.pex3 = p.tyre.pkx2 = p.tyre.pkx3 = 0.0;
  p.chassis.drag_coefficient = 0.0;
  p.chassis.rolling_resistance = 0.0;
  return p;
}

}  // namespace bbw::test
