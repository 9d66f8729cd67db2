#include "bbw/plant/population.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "bbw/plant/key_friction.hpp"

namespace bbw::plant {
namespace {

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

void check(const char* name, const Interval& i, double lo, double hi) {
  if (!std::isfinite(i.min) || !std::isfinite(i.max) || i.min > i.max || i.min < lo || i.max > hi) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "population ranges: %s = [%g, %g] must satisfy %g <= min <= max <= %g", name,
                  i.min, i.max, lo, hi);
    throw std::invalid_argument(buf);
  }
}

double uniform(std::mt19937_64& rng, const Interval& i) {
  return std::uniform_real_distribution<double>(i.min, i.max)(rng);
}

double log_uniform(std::mt19937_64& rng, const Interval& i) {
  return std::exp(std::uniform_real_distribution<double>(std::log(i.min), std::log(i.max))(rng));
}

}  // namespace

void PopulationRanges::validate() const {
  check("elements", elements, 1, 1000);
  check("threshold_min_rev", threshold_min_rev, 1e-5, 5.0);
  if (threshold_min_rev.min <= 0.0) throw std::invalid_argument("population ranges: threshold_min_rev must be > 0");
  check("threshold_span_ratio", threshold_span_ratio, 1.0, 1e6);
  if (!(threshold_max_limit_rev >= threshold_min_rev.max) || !(threshold_max_limit_rev <= 5.0)) {
    throw std::invalid_argument("population ranges: threshold_max_limit_rev = " + std::to_string(threshold_max_limit_rev) +
                                " must be in [threshold_min_rev.max, 5]");
  }
  if (!(log_uniform_share >= 0.0 && log_uniform_share <= 1.0)) {
    throw std::invalid_argument("population ranges: log_uniform_share must be in [0, 1]");
  }
  check("half_width_kN", half_width_kN, 1e-6, 100.0);
  check("force_share_exponent", force_share_exponent, -3.0, 3.0);
  check("share_log_sigma", share_log_sigma, 0.0, 3.0);
  check("initial_deflection", initial_deflection, -1.0, 1.0);
  check("contact_rev", contact_rev, -2.0, 10.0);
  check("stiffness_scale", stiffness_scale, 0.01, 100.0);
  check("contact_shift_rev_per_C", contact_shift_rev_per_C, -1.0, 1.0);
  check("stiffness_change_per_C", stiffness_change_per_C, -0.01, 0.01);
  check("load_cell_noise_kN", load_cell_noise_kN, 0.0, 10.0);
}

Caliper draw_caliper(const PlantParams& base, const PopulationRanges& r, std::uint64_t seed, int index) {
  r.validate();
  if (index < 0) throw std::invalid_argument("draw_caliper: index must be >= 0");
  Caliper c;
  c.index = index;
  c.seed = splitmix64(seed ^ splitmix64(static_cast<std::uint64_t>(index) + 1));
  std::mt19937_64 rng(c.seed);
  PlantParams p = base;
  KeyFrictionParams& k = p.key_friction;
  k.elements = static_cast<int>(std::floor(uniform(rng, Interval{r.elements.min, r.elements.max + 1.0 - 1e-9})));
  const double lo = log_uniform(rng, r.threshold_min_rev);
  const double hi = std::max(lo, std::min(lo * log_uniform(rng, r.threshold_span_ratio), r.threshold_max_limit_rev));
  k.threshold_min_rev = lo;
  k.threshold_max_rev = hi;
  const bool log_uniform_thresholds = std::uniform_real_distribution<double>(0.0, 1.0)(rng) < r.log_uniform_share;
  k.threshold_distribution = log_uniform_thresholds ? ThresholdDistribution::LogUniform : ThresholdDistribution::LogNormal;
  // Log-normal: median at the geometric middle, +/- 2 sigma across the span (then clipped).
  k.threshold_median_rev = std::sqrt(lo * hi);
  k.threshold_log_sigma = std::min(3.0, std::log(hi / lo) / 4.0);
  k.half_width_kN = uniform(rng, r.half_width_kN);
  k.force_share_exponent = uniform(rng, r.force_share_exponent);
  k.share_log_sigma = uniform(rng, r.share_log_sigma);
  k.initial_deflection = uniform(rng, r.initial_deflection);
  k.structure_seed = rng() >> 1;
  ClampCurveParams& cv = p.curve;
  cv.contact_rev = uniform(rng, r.contact_rev);
  c.stiffness_scale = uniform(rng, r.stiffness_scale);
  cv.exp_coefficient_kN *= c.stiffness_scale;
  cv.linear_kN_per_rev *= c.stiffness_scale;
  cv.contact_shift_rev_per_C = uniform(rng, r.contact_shift_rev_per_C);
  cv.stiffness_change_per_C = uniform(rng, r.stiffness_change_per_C);
  p.sensors.load_cell_noise_kN = uniform(rng, r.load_cell_noise_kN);
  p.validate();
  c.params = p;
  return c;
}

std::string describe_key_friction(const KeyFrictionParams& k) {
  const KeyFriction f(k);
  const auto& d = f.thresholds_rev();
  char buf[160];
  std::snprintf(buf, sizeof buf, "%d el, %s %.4f-%.3f rev, %.2f kN, n0 %+.2f", k.elements,
                k.threshold_distribution == ThresholdDistribution::LogUniform ? "log-uniform" : "log-normal",
                d.front(), d.back(), k.half_width_kN, k.initial_deflection);
  return buf;
}

}  // namespace bbw::plant
