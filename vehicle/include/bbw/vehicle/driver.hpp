// A driver who steers to follow a path (straight along +x, or a circle of the given radius,
// starting at the origin heading +x, left turns positive): a preview controller on the
// lateral offset at a look-ahead distance plus the path's curvature as feed-forward, acting
// through a reaction delay and a first-order steering lag with a rate limit. Pure.
#pragma once

#include <array>
#include <cstddef>

namespace bbw::vehicle {

struct DriverParams {
  double path_radius_m = 0.0;        // 0: straight; > 0 left turn, < 0 right turn
  double preview_s = 0.8;            // look-ahead time
  double gain_rad_per_m = 0.02;      // steering per metre of previewed offset
  double yaw_rate_gain_s = 0.0;      // counter-steer per rad/s of yaw rate beyond the path's (rad per rad/s)
  double reaction_s = 0.15;          // delay from seeing to steering
  double lag_s = 0.1;                // steering first-order lag
  double max_rate_rad_s = 0.6;       // road-wheel steering rate limit
  double max_steer_rad = 0.3;

  void validate() const;
};

struct PathError {
  double lateral_m = 0.0;   // positive: left of the path
  double heading_rad = 0.0; // vehicle heading minus path heading
};

// The offset of a point and heading from the path.
PathError path_error(double path_radius_m, double x_m, double y_m, double yaw_rad);

class Driver {
 public:
  Driver(const DriverParams& p, double wheelbase_m);
  // Steering for the next step given where the car is; dt_s the step.
  double steer(double dt_s, double x_m, double y_m, double yaw_rad, double speed_m_s, double yaw_rate_rad_s = 0.0);
  double steer_rad() const { return steer_rad_; }

 private:
  DriverParams p_;
  double wheelbase_m_;
  std::array<double, 1024> delay_{};  // commanded steering, one per step (ring)
  std::size_t head_ = 0;
  std::size_t delay_steps_ = 0;
  double steer_rad_ = 0.0;
  bool first_ = true;
};

}  // namespace bbw::vehicle
