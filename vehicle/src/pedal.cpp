#include "bbw/vehicle/pedal.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bbw::vehicle {

void PedalParams::validate() const {
  if (!(full_travel_mm > 0.0) || !(full_force_N > 0.0) || !(force_exponent >= 1.0 && force_exponent <= 3.0) ||
      !(travel_noise_mm >= 0.0) || !(force_noise_N >= 0.0)) {
    throw std::invalid_argument(
        "pedal: full_travel_mm, full_force_N > 0, force_exponent in [1, 3], noises >= 0");
  }
}

Pedal::Pedal(const PedalParams& p, std::vector<std::pair<double, double>> profile, std::uint64_t seed)
    : p_(p), profile_(std::move(profile)), rng_(seed) {
  p_.validate();
  if (profile_.empty()) throw std::invalid_argument("pedal: empty travel profile");
  for (std::size_t i = 0; i < profile_.size(); ++i) {
    if (profile_[i].second < 0.0 || profile_[i].second > 1.0) throw std::invalid_argument("pedal: travel fraction outside [0, 1]");
    if (i > 0 && !(profile_[i].first > profile_[i - 1].first)) throw std::invalid_argument("pedal: times must increase");
  }
}

double Pedal::travel_fraction(double t) const {
  if (t <= profile_.front().first) return profile_.front().second;
  for (std::size_t i = 1; i < profile_.size(); ++i) {
    if (t <= profile_[i].first) {
      const auto& [t0, v0] = profile_[i - 1];
      const auto& [t1, v1] = profile_[i];
      return v0 + (v1 - v0) * (t - t0) / (t1 - t0);
    }
  }
  return profile_.back().second;
}

PedalReading Pedal::read(double time_s) {
  const double f = travel_fraction(time_s);
  PedalReading r;
  r.travel_mm = f * p_.full_travel_mm + p_.travel_noise_mm * normal_(rng_);
  r.force_N = p_.full_force_N * std::pow(f, p_.force_exponent) + p_.force_noise_N * normal_(rng_);
  return r;
}

}  // namespace bbw::vehicle
