// Vehicle::step, the wheel-speed sensor, the IMU and the driver do not allocate.
#include <gtest/gtest.h>

#include "alloc_counter.hpp"
#include "bbw/vehicle/driver.hpp"
#include "bbw/vehicle/sensors.hpp"
#include "bbw/vehicle/vehicle.hpp"

using namespace bbw::vehicle;

TEST(VehicleAllocation, StepAndSensorsAreAllocationFree) {
  VehicleParams p;
  RoadParams r;
  r.surfaces = {{"dry", 0.85, 0.85}, {"ice", 0.085, 0.085}};
  r.patches = {{0, 1000, 0, 100, 1}, {30, 40, -100, 100, 1}};
  Vehicle v(p, r);
  v.reset(27.0, {20, 20, 20, 20}, {20, 20, 20, 20});
  WheelSpeedSensor s({}, 1);
  s.reset(0.0, 0.0);
  Imu imu({}, 2);
  Driver d({}, 2.6);
  VehicleInputs in;
  in.clamp_force_kN = {10, 10, 6, 6};
  const long before = bbw::test::allocation_count();
  for (int i = 0; i < 3000; ++i) {
    in.steer_rad = d.steer(0.001, v.state().x_m, v.state().y_m, v.state().yaw_rad, v.speed_m_s());
    v.step(0.001, in);
    s.update(v.state().wheels[0].angle_rad, v.state().time_s);
    (void)s.speed_rad_s(v.state().time_s);
    (void)imu.read(v.state().ax_m_s2, v.state().ay_m_s2, v.state().yaw_rate_rad_s);
  }
  EXPECT_EQ(bbw::test::allocation_count() - before, 0);
}
