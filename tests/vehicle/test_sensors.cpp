// The toothed wheel (edge timing, quantisation, pitch errors, timeout), the IMU (bias and
// noise, seeded), the pedal's two sensors and the steering driver.
#include <gtest/gtest.h>

#include <cmath>

#include "bbw/vehicle/driver.hpp"
#include "bbw/vehicle/pedal.hpp"
#include "bbw/vehicle/sensors.hpp"

using namespace bbw::vehicle;

TEST(WheelSpeedSensor, ReadsAConstantSpeedWithinThePitchError) {
  WheelSpeedSensorParams p;
  WheelSpeedSensor s(p, 7);
  const double w = 50.0;  // rad/s
  s.reset(0.0, 0.0);
  double max_err = 0.0;
  for (int i = 1; i <= 2000; ++i) {
    const double t = i * 1e-3;
    s.update(w * t, t);
    if (i > 20) max_err = std::max(max_err, std::abs(s.speed_rad_s(t) - w) / w);
  }
  EXPECT_GT(max_err, 1e-5);   // the pitch errors and the timer show
  EXPECT_LT(max_err, 0.02);   // a few pitch-error sigmas
  EXPECT_GT(s.edges(), 700u);
}

TEST(WheelSpeedSensor, QuantisesEdgeTimes) {
  WheelSpeedSensorParams p;
  p.pitch_error = 0.0;
  p.timer_resolution_s = 1e-3;  // coarse: the reading jumps between interval counts
  WheelSpeedSensor s(p, 1);
  const double w = 100.0;
  s.reset(0.0, 0.0);
  for (int i = 1; i <= 1000; ++i) s.update(w * i * 1e-4, i * 1e-4);
  const double pitch = 2.0 * M_PI / 48.0;
  const double reading = s.speed_rad_s(0.1);
  const double intervals = pitch / reading / 1e-3;
  EXPECT_NEAR(intervals, std::round(intervals), 1e-9);
}

TEST(WheelSpeedSensor, ReadsZeroAfterTheTimeoutAndBoundsASlowingWheel) {
  WheelSpeedSensorParams p;
  WheelSpeedSensor s(p, 3);
  s.reset(0.0, 0.0);
  for (int i = 1; i <= 100; ++i) s.update(20.0 * i * 1e-3, i * 1e-3);
  const double before = s.speed_rad_s(0.1);
  EXPECT_NEAR(before, 20.0, 0.5);
  // The wheel locks: no more edges.
  for (int i = 101; i <= 200; ++i) s.update(2.0, i * 1e-3);
  EXPECT_LT(s.speed_rad_s(0.15), before);
  EXPECT_EQ(s.speed_rad_s(0.1 + p.timeout_s + 0.01), 0.0);
}

TEST(Imu, IsSeededAndBiased) {
  ImuParams p;
  Imu a(p, 5), b(p, 5);
  double mean = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const ImuReading ra = a.read(-3.0, 0.0, 0.0), rb = b.read(-3.0, 0.0, 0.0);
    ASSERT_EQ(ra.ax_m_s2, rb.ax_m_s2);
    mean += ra.ax_m_s2 / 20000.0;
  }
  EXPECT_NEAR(std::abs(mean + 3.0), p.accel_bias_m_s2, 0.003);
}

TEST(Pedal, TwoSensorsFollowTheProfile) {
  PedalParams p;
  Pedal pedal(p, {{0.0, 0.0}, {1.0, 1.0}}, 9);
  EXPECT_DOUBLE_EQ(pedal.travel_fraction(0.5), 0.5);
  const PedalReading r = pedal.read(0.5);
  EXPECT_NEAR(r.travel_mm, 40.0, 1.0);
  EXPECT_NEAR(r.force_N, 500.0 * std::pow(0.5, 1.6), 8.0);
  EXPECT_THROW(Pedal(p, {{0.0, 0.0}, {0.0, 1.0}}, 1), std::invalid_argument);
  EXPECT_THROW(Pedal(p, {{0.0, 1.5}}, 1), std::invalid_argument);
}

TEST(Driver, SteersBackToThePath) {
  DriverParams p;
  Driver d(p, 2.6);
  double steer = 0.0;
  for (int i = 0; i < 1000; ++i) steer = d.steer(0.001, 10.0, 0.5, 0.0, 20.0);  // 0.5 m left of the path
  EXPECT_LT(steer, -0.005);
  const PathError e = path_error(50.0, 0.0, 1.0, 0.0);  // inside a left circle of radius 50
  EXPECT_NEAR(e.lateral_m, 1.0, 1e-9);
  EXPECT_NEAR(e.heading_rad, 0.0, 1e-9);
  EXPECT_THROW(Driver(DriverParams{2.0}, 2.6), std::invalid_argument);
}
