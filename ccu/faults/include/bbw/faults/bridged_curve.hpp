// The curve a corner is left with when its load cell is lost (docs/faults.md, "Reaction" and
// "Twenty-ninth session"): the newest fit before the fault where that fit had data, the caliper's
// end-of-line curve's shape beyond. Pure; no allocation.
#pragma once

#include "bbw/model/curve.hpp"
#include "bbw/plant/clamp_curve.hpp"

namespace bbw::faults {

// The position span a fitted curve's data covered (empty: lo > hi, e.g. before any fit).
struct DataSpan {
  double lo_rev = 1.0;
  double hi_rev = 0.0;
  bool empty() const { return !(hi_rev >= lo_rev); }
};

// One cubic over [from_rev, to_rev] (least squares on 64 evenly spaced points, each weighed by
// 1 / (1 + F / 10 kN): within 0.3 kN released and 3 % at 20-40 kN on a 0.4 x caliper) through
//   g(x) = fitted(xb) + eol(x) - eol(xb),  xb = x clamped to `data`,
// the fit where it had data and the end-of-line curve's rise beyond, continuous at the span's
// ends; g = eol where the span is empty. eol at temperature_C, no wear.
// A cubic fitted from PF points over a caliper's configured range keeps its initial curve's
// values where no cycle came and extrapolates past the range's top: on a caliper 0.4 x as stiff
// as the shipped one it read 33.6 kN at 7.7 rev where the clamp force was 14.6 (faster-driver
// campaign `fast`, run 68).
// Throws std::invalid_argument if from_rev >= to_rev or either is not finite.
model::Curve bridge_curve(const model::Curve& fitted, const DataSpan& data, const plant::ClampCurve& eol,
                          double temperature_C, double from_rev, double to_rev);

// The position where the end-of-line curve at temperature_C reaches force_kN (bisection over
// [lo_rev, hi_rev]; hi_rev if it does not reach it there).
double eol_position_at(const plant::ClampCurve& eol, double force_kN, double temperature_C, double lo_rev,
                       double hi_rev);

}  // namespace bbw::faults
