#include "bbw/vehicle/driver.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bbw::vehicle {

void DriverParams::validate() const {
  if (!std::isfinite(path_radius_m) || (path_radius_m != 0.0 && std::abs(path_radius_m) < 5.0)) {
    throw std::invalid_argument("driver.path_radius_m must be 0 (straight) or at least 5 m in magnitude");
  }
  if (!(preview_s >= 0.0) || !(gain_rad_per_m >= 0.0) || !(yaw_rate_gain_s >= 0.0 && yaw_rate_gain_s <= 2.0) || !(reaction_s >= 0.0 && reaction_s <= 0.5) ||
      !(lag_s > 0.0) || !(max_rate_rad_s > 0.0) || !(max_steer_rad > 0.0 && max_steer_rad < 0.7)) {
    throw std::invalid_argument(
        "driver: preview_s and gain_rad_per_m >= 0, yaw_rate_gain_s in [0, 2], reaction_s in [0, 0.5], lag_s > 0, max_rate_rad_s > 0, "
        "max_steer_rad in (0, 0.7)");
  }
}

PathError path_error(double R, double x_m, double y_m, double yaw_rad) {
  PathError e;
  if (R == 0.0) {
    e.lateral_m = y_m;
    e.heading_rad = yaw_rad;
    return e;
  }
  // Circle centred at (0, R): a left turn for R > 0.
  const double dx = x_m, dy = y_m - R;
  const double dist = std::hypot(dx, dy);
  e.lateral_m = R > 0.0 ? (R - dist) : (dist - (-R));
  if (R < 0.0) e.lateral_m = -e.lateral_m;
  // Path heading at the nearest point: the tangent of the circle.
  const double ang = std::atan2(dy, dx);  // from the centre
  const double path_heading = R > 0.0 ? ang + 1.5707963267948966 : ang - 1.5707963267948966;
  e.heading_rad = std::remainder(yaw_rad - path_heading, 6.283185307179586);
  return e;
}

Driver::Driver(const DriverParams& p, double wheelbase_m) : p_(p), wheelbase_m_(wheelbase_m) { p_.validate(); }

double Driver::steer(double dt_s, double x_m, double y_m, double yaw_rad, double speed_m_s, double yaw_rate_rad_s) {
  if (first_) {
    delay_steps_ = std::min<std::size_t>(delay_.size() - 1, static_cast<std::size_t>(std::lround(p_.reaction_s / dt_s)));
    first_ = false;
  }
  const PathError e = path_error(p_.path_radius_m, x_m, y_m, yaw_rad);
  const double previewed = e.lateral_m + p_.preview_s * speed_m_s * std::sin(e.heading_rad);
  const double feed_forward = p_.path_radius_m == 0.0 ? 0.0 : wheelbase_m_ / p_.path_radius_m;
  const double path_yaw_rate = p_.path_radius_m == 0.0 ? 0.0 : speed_m_s / p_.path_radius_m;
  const double wanted = std::clamp(feed_forward - p_.gain_rad_per_m * previewed - p_.yaw_rate_gain_s * (yaw_rate_rad_s - path_yaw_rate),
                                   -p_.max_steer_rad, p_.max_steer_rad);
  delay_[head_] = wanted;
  const std::size_t tail = (head_ + delay_.size() - delay_steps_) % delay_.size();
  head_ = (head_ + 1) % delay_.size();
  const double seen = delay_[tail];
  const double rate = std::clamp((seen - steer_rad_) / p_.lag_s, -p_.max_rate_rad_s, p_.max_rate_rad_s);
  steer_rad_ += dt_s * rate;
  return steer_rad_;
}

}  // namespace bbw::vehicle
