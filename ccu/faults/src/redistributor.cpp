#include "bbw/faults/redistributor.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bbw::faults {
namespace {

// Gives `amount` to corners a and b (equal split, each capped at its headroom); returns what
// neither could take.
double fill_pair(double amount, std::size_t a, std::size_t b, const std::array<CornerCapacity, kCorners>& c,
                 std::array<double, kCorners>& f) {
  auto headroom = [&](std::size_t i) { return c[i].available ? std::max(0.0, c[i].limit_kN - f[i]) : 0.0; };
  double left = amount;
  for (int pass = 0; pass < 2 && left > 0.0; ++pass) {
    const double ha = headroom(a), hb = headroom(b);
    const int n = (ha > 0.0 ? 1 : 0) + (hb > 0.0 ? 1 : 0);
    if (n == 0) break;
    const double each = left / n;
    const double ga = std::min(ha, ha > 0.0 ? each : 0.0);
    const double gb = std::min(hb, hb > 0.0 ? each : 0.0);
    f[a] += ga;
    f[b] += gb;
    left -= ga + gb;
  }
  return std::max(0.0, left);
}

}  // namespace

Redistributor::Redistributor(double front_share) : front_share_(front_share) {
  if (!(front_share >= 0.5 && front_share <= 0.9)) {
    throw std::invalid_argument("Redistributor: front_share = " + std::to_string(front_share) + ": must be in [0.5, 0.9]");
  }
}

double Redistributor::nominal_kN(std::size_t slot, double total_demand_kN) const {
  const double axle = slot < 2 ? front_share_ : 1.0 - front_share_;
  return 0.5 * axle * std::max(0.0, total_demand_kN);
}

Allocation Redistributor::allocate(double total_demand_kN, const std::array<CornerCapacity, kCorners>& corners) const {
  Allocation a;
  const double total = std::isfinite(total_demand_kN) ? std::max(0.0, total_demand_kN) : 0.0;
  auto held = [&](std::size_t i) {
    const double h = corners[i].held_kN;
    return !corners[i].available && std::isfinite(h) ? std::max(0.0, h) : 0.0;
  };
  const double front_held = held(0) + held(1);
  const double rear_held = held(2) + held(3);
  a.held_kN = front_held + rear_held;
  const double front_left = fill_pair(std::max(0.0, front_share_ * total - front_held), 0, 1, corners, a.force_kN);
  const double rear_left = fill_pair(std::max(0.0, (1.0 - front_share_) * total - rear_held), 2, 3, corners, a.force_kN);
  // What one axle cannot deliver goes to the other.
  const double rear_spill = fill_pair(front_left, 2, 3, corners, a.force_kN);
  const double front_spill = fill_pair(rear_left, 0, 1, corners, a.force_kN);
  a.shortfall_kN = rear_spill + front_spill;
  for (double f : a.force_kN) a.total_kN += f;
  return a;
}

}  // namespace bbw::faults
