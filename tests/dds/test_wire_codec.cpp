// The wire codec, message by message: every IDL type survives CDR serialisation (the generated
// PubSubType, what Fast DDS puts on the wire) with every field set to a distinct value, and the
// domain conversions in dds/src/convert.cpp carry every field they promise (one place where
// messages and domain structs meet; docs/architecture.md, "Adding a message").
#include <gtest/gtest.h>

#include <bbw/idl/bbw_msgsPubSubTypes.h>
#include <fastdds/rtps/common/SerializedPayload.h>

#include "bbw/calibration/config.hpp"
#include "bbw/dds/convert.hpp"

namespace bbw::dds {

namespace {

template <class PubSubT>
typename PubSubT::type round_trip(typename PubSubT::type& in) {
  PubSubT type;
  const std::uint32_t size = type.getSerializedSizeProvider(&in)();
  eprosima::fastrtps::rtps::SerializedPayload_t payload(size);
  EXPECT_TRUE(type.serialize(&in, &payload));
  typename PubSubT::type out;
  EXPECT_TRUE(type.deserialize(&payload, &out));
  return out;
}

msg::MeasurementSample sample(double base) {
  msg::MeasurementSample s;
  s.seq(static_cast<unsigned long long>(base * 10));
  s.time_s(base + 0.001);
  s.position_rev(base + 0.002);
  s.speed_rev_per_s(base + 0.003);
  s.force_internal_kN(base + 0.004);
  s.force_external_kN(base + 0.005);
  s.force_true_kN(base + 0.006);
  s.temperature_C(base + 0.007);
  s.motor_current_A(base + 0.008);
  s.command(base + 0.009);
  s.status(msg::STATUS_FORCE_MODE | msg::STATUS_FRICTION_COMP);
  return s;
}

}  // namespace

TEST(WireCodec, MeasurementBlockWithItsSamples) {
  msg::MeasurementBlock b;
  b.corner_id(3);
  b.run_id(0x0123456789abcdefULL);
  b.block_seq(4711);
  b.period_start_s(23.555);
  b.first_sample_seq(23551);
  b.incarnation(2);
  for (int i = 0; i < static_cast<int>(msg::MAX_BLOCK_SAMPLES); ++i) b.samples().push_back(sample(1.0 + i));
  const auto out = round_trip<msg::MeasurementBlockPubSubType>(b);
  EXPECT_TRUE(out == b);
  ASSERT_EQ(out.samples().size(), msg::MAX_BLOCK_SAMPLES);
  EXPECT_EQ(out.samples()[63].speed_rev_per_s(), 64.003);
}

TEST(WireCodec, ClampCommand) {
  msg::ClampCommand c;
  c.corner_id(1);
  c.run_id(77);
  c.seq(9);
  c.step(10);
  c.time_s(0.05);
  c.clamp_force_kN(12.5);
  c.mode(msg::MODE_FORCE);
  c.valid(true);
  c.use_friction_comp(true);
  c.calibration_version(3);
  c.friction_estimate_kN(0.55);
  c.stop(true);
  c.feedback_override(msg::FEEDBACK_CURVE);
  c.override_curve_a_kN_per_rev3(0.1);
  c.override_curve_b_kN_per_rev2(0.2);
  c.override_curve_c_kN_per_rev(3.3);
  c.override_curve_d_kN(-0.4);
  EXPECT_TRUE(round_trip<msg::ClampCommandPubSubType>(c) == c);
}

TEST(WireCodec, CalibrationStateWithFullSequences) {
  msg::CalibrationState s;
  s.corner_id(2);
  s.run_id(5);
  s.version(6);
  s.time_s(7.5);
  s.curve_a_kN_per_rev3(0.11);
  s.curve_b_kN_per_rev2(0.22);
  s.curve_c_kN_per_rev(3.33);
  s.curve_d_kN(-0.44);
  std::vector<double> d, k;
  for (int i = 0; i < static_cast<int>(msg::MAX_FRICTION_ELEMENTS); ++i) {
    d.push_back(0.001 * (i + 1));
    k.push_back(10.0 + i);
  }
  s.friction_delta_rev(d);
  s.friction_stiffness_kN_per_rev(k);
  s.friction_viscous_kN_per_rev_per_s(0.05);
  s.friction_load_gain(0.3);
  s.friction_load_reference_kN(35.0);
  s.backlash_width_rev(0.01);
  s.load_cell_offset_kN_per_C(0.02);
  s.load_cell_offset_reference_C(41.0);
  s.fits_accepted(12);
  s.fits_rejected(1);
  s.cycles_detected(14);
  s.last_fit_rms_kN(0.03);
  s.last_fit_span_rev(2.5);
  EXPECT_TRUE(round_trip<msg::CalibrationStatePubSubType>(s) == s);
}

TEST(WireCodec, CornerHealth) {
  msg::CornerHealth h;
  h.corner_id(0);
  h.run_id(99);
  h.status(msg::HEALTH_RUNNING);
  h.samples_published(1000);
  h.blocks_published(200);
  h.commands_received(201);
  h.commands_applied(199);
  h.command_seq_gaps(2);
  h.overruns(3);
  h.max_jitter_s(0.0012);
  h.time_s(1.0);
  h.incarnation(1);
  h.resume_step(400);
  EXPECT_TRUE(round_trip<msg::CornerHealthPubSubType>(h) == h);
}

TEST(WireCodec, ACornerSampleBecomesAWireSampleFieldByField) {
  scenario::CornerSample c;
  c.seq = 42;
  c.time_s = 0.042;
  c.position_rev = 2.5;
  c.speed_rev_per_s = -1.25;
  c.force_internal_kN = 10.5;
  c.force_external_kN = 10.0;
  c.force_true_kN = 9.9;
  c.temperature_C = 44.0;
  c.motor_current_A = 7.5;
  c.command = 10.0;
  c.command_kind = scenario::CommandKind::Force;
  msg::MeasurementSample m;
  to_msg(c, true, m);
  EXPECT_EQ(m.seq(), 42u);
  EXPECT_EQ(m.time_s(), 0.042);
  EXPECT_EQ(m.position_rev(), 2.5);
  EXPECT_EQ(m.speed_rev_per_s(), -1.25);
  EXPECT_EQ(m.force_internal_kN(), 10.5);
  EXPECT_EQ(m.force_external_kN(), 10.0);
  EXPECT_EQ(m.force_true_kN(), 9.9);
  EXPECT_EQ(m.temperature_C(), 44.0);
  EXPECT_EQ(m.motor_current_A(), 7.5);
  EXPECT_EQ(m.command(), 10.0);
  EXPECT_TRUE(m.status() & msg::STATUS_FORCE_MODE);
  EXPECT_TRUE(m.status() & msg::STATUS_FRICTION_COMP);
  EXPECT_TRUE(m.status() & msg::STATUS_SIM_TRUTH_VALID);
  to_msg(c, false, m);
  EXPECT_FALSE(m.status() & msg::STATUS_FRICTION_COMP);
}

TEST(WireCodec, ACalibrationStateSurvivesTheWireIntoTheCornersModel) {
  msg::CalibrationState s;
  s.corner_id(1);
  s.version(4);
  s.curve_a_kN_per_rev3(0.1);
  s.curve_b_kN_per_rev2(0.2);
  s.curve_c_kN_per_rev(3.0);
  s.curve_d_kN(-1.0);
  s.friction_delta_rev({0.01, 0.1});
  s.friction_stiffness_kN_per_rev({5.0, 6.0});
  s.friction_load_reference_kN(40.0);
  s.load_cell_offset_reference_C(40.0);
  s.backlash_width_rev(0.02);
  const auto wire = round_trip<msg::CalibrationStatePubSubType>(s);
  CalibrationModel m;
  ASSERT_TRUE(from_msg(wire, m));
  EXPECT_EQ(m.version, 4u);
  EXPECT_EQ(m.curve.a, 0.1);
  EXPECT_EQ(m.curve.d, -1.0);
  EXPECT_EQ(m.friction.delta_rev, (std::vector<double>{0.01, 0.1}));
  EXPECT_EQ(m.friction.stiffness_kN_per_rev, (std::vector<double>{5.0, 6.0}));
  EXPECT_EQ(m.friction.backlash_width_rev, 0.02);
  s.backlash_width_rev(5.0);  // beyond the calibrator's bounds: refused, the model untouched
  EXPECT_FALSE(from_msg(round_trip<msg::CalibrationStatePubSubType>(s), m));
  EXPECT_EQ(m.friction.backlash_width_rev, 0.02);
}

}  // namespace bbw::dds
