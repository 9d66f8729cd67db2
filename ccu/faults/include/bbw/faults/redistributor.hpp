// Sharing the demanded total clamp force among the corners that can brake (docs/faults.md,
// "Redistribution"). Pure arithmetic, allocation-free.
//
// Rule: the front axle is asked for front_share of the total and the rear for the rest (the
// vehicle's brake balance). On each axle the available corners share their axle's part
// equally, each capped by its force limit (what one cannot take goes to its partner). What an
// axle cannot deliver goes to the other axle's available corners, again capped. What nobody
// can take is the shortfall. So a lost front corner's share goes first to the other front
// corner (keeping the front/rear balance, which decides stability under braking) and only
// beyond its limit to the rear; the side-to-side imbalance this creates is left to the
// vehicle's yaw control (steering/ESC), which this simulation does not model.
//
// An unavailable corner may still brake: one whose actuator does not release holds held_kN.
// That force counts towards its own axle's part (the partner is asked for less, down to 0);
// what it holds beyond its axle's part is not taken off the other axle (a jammed rear brake
// must not shift the balance to the rear), so the total can then exceed the demand.
#pragma once

#include <array>
#include <cstddef>

namespace bbw::faults {

inline constexpr std::size_t kCorners = 4;  // FL, FR, RL, RR (corner_slot order)

struct CornerCapacity {
  bool available = true;
  double limit_kN = 40.0;
  double held_kN = 0.0;  // force an unavailable corner delivers anyway (ignored when available)
};

struct Allocation {
  std::array<double, kCorners> force_kN{};  // commands; 0 for unavailable corners
  double total_kN = 0.0;                    // sum of force_kN (held forces not included)
  double held_kN = 0.0;                     // sum of the unavailable corners' held forces
  double shortfall_kN = 0.0;                // demand that no available corner could take
};

class Redistributor {
 public:
  // front_share in [0.5, 0.9] (scenario::DemandSpec). Throws std::invalid_argument.
  explicit Redistributor(double front_share);

  Allocation allocate(double total_demand_kN, const std::array<CornerCapacity, kCorners>& corners) const;
  // The nominal (all available, no limits reached) force of corner slot i for a total demand.
  double nominal_kN(std::size_t slot, double total_demand_kN) const;
  double front_share() const { return front_share_; }

 private:
  double front_share_;
};

}  // namespace bbw::faults
