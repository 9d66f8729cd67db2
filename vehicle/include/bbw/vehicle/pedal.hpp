// The instrumented brake pedal: the driver's travel profile (fraction of full travel over time)
// read by two redundant sensors, a travel sensor (mm) and a force sensor (N, through the pedal's
// feel curve), each with noise (seeded). The CCU turns the two into one demand
// (bbw/brake/pedal_demand.hpp). Pure.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

namespace bbw::vehicle {

struct PedalParams {
  double full_travel_mm = 80.0;
  double full_force_N = 500.0;      // force at full travel
  double force_exponent = 1.6;      // feel curve F = full_force (travel / full_travel)^exponent
  double travel_noise_mm = 0.1;
  double force_noise_N = 1.5;

  void validate() const;
};

struct PedalReading {
  double travel_mm = 0.0;
  double force_N = 0.0;
};

class Pedal {
 public:
  // profile: [t_s, travel fraction 0..1] breakpoints, linear in between (held after the last).
  Pedal(const PedalParams& p, std::vector<std::pair<double, double>> profile, std::uint64_t seed);
  double travel_fraction(double time_s) const;
  PedalReading read(double time_s);
  const PedalParams& params() const { return p_; }

 private:
  PedalParams p_;
  std::vector<std::pair<double, double>> profile_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace bbw::vehicle
