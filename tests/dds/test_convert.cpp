// The CalibrationState a CCU publishes carries its calibrator's whole friction model, optional
// effect terms included, and a corner refuses one whose terms break the calibrator's bounds.
#include <gtest/gtest.h>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/dds/convert.hpp"

namespace {

using namespace bbw;

calibration::CalibratorConfig config_with_terms() {
  calibration::CalibratorConfig c;
  c.viscous_friction = true;
  c.load_friction_gain = 0.9;
  c.load_friction_reference_kN = 35.7;
  c.backlash_width_rev = 0.042;
  c.load_cell_offset_kN_per_C = 0.02;
  c.load_cell_offset_reference_C = 38.0;
  return c;
}

TEST(CalibrationStateConvert, CarriesTheEffectTermsToTheCorner) {
  calibration::Calibrator cal(config_with_terms());
  cal.set_friction_stiffness(std::vector<double>(cal.friction().delta_rev.size(), 1.5));
  msg::CalibrationState state;
  dds::to_msg(cal, 2, 7, 1.25, state);
  dds::CalibrationModel m;
  ASSERT_TRUE(dds::from_msg(state, m));
  EXPECT_EQ(m.version, 7u);
  EXPECT_EQ(m.friction.delta_rev, cal.friction().delta_rev);
  EXPECT_EQ(m.friction.stiffness_kN_per_rev, cal.friction().stiffness_kN_per_rev);
  EXPECT_DOUBLE_EQ(m.friction.viscous_kN_per_rev_per_s, cal.friction().viscous_kN_per_rev_per_s);
  EXPECT_DOUBLE_EQ(m.friction.load_gain, 0.9);
  EXPECT_DOUBLE_EQ(m.friction.load_reference_kN, 35.7);
  EXPECT_DOUBLE_EQ(m.friction.backlash_width_rev, 0.042);
  EXPECT_DOUBLE_EQ(m.friction.load_cell_offset_kN_per_C, 0.02);
  EXPECT_DOUBLE_EQ(m.friction.load_cell_offset_reference_C, 38.0);
}

TEST(CalibrationStateConvert, TermsOffAreZero) {
  calibration::Calibrator cal(calibration::CalibratorConfig{});
  msg::CalibrationState state;
  dds::to_msg(cal, 0, 1, 0.0, state);
  dds::CalibrationModel m;
  ASSERT_TRUE(dds::from_msg(state, m));
  EXPECT_EQ(m.friction.viscous_kN_per_rev_per_s, 0.0);
  EXPECT_EQ(m.friction.load_gain, 0.0);
  EXPECT_EQ(m.friction.backlash_width_rev, 0.0);
}

TEST(CalibrationStateConvert, RefusesTermsOutOfTheirBounds) {
  calibration::Calibrator cal(config_with_terms());
  msg::CalibrationState good;
  dds::to_msg(cal, 1, 3, 0.5, good);
  const auto refused = [&](auto&& spoil) {
    msg::CalibrationState s = good;
    spoil(s);
    dds::CalibrationModel m;
    m.version = 99;
    const bool ok = dds::from_msg(s, m);
    if (!ok) {
      EXPECT_EQ(m.version, 99u) << "a refused message changed the model";
    }
    return !ok;
  };
  EXPECT_TRUE(refused([](msg::CalibrationState& s) { s.friction_viscous_kN_per_rev_per_s(-0.1); }));
  EXPECT_TRUE(refused([](msg::CalibrationState& s) { s.friction_viscous_kN_per_rev_per_s(std::nan("")); }));
  EXPECT_TRUE(refused([](msg::CalibrationState& s) { s.friction_load_gain(11.0); }));
  EXPECT_TRUE(refused([](msg::CalibrationState& s) { s.friction_load_reference_kN(0.0); }));
  EXPECT_TRUE(refused([](msg::CalibrationState& s) { s.backlash_width_rev(0.6); }));
  EXPECT_TRUE(refused([](msg::CalibrationState& s) { s.load_cell_offset_kN_per_C(2.0); }));
  EXPECT_TRUE(refused([](msg::CalibrationState& s) { s.load_cell_offset_reference_C(std::nan("")); }));
  EXPECT_FALSE(refused([](msg::CalibrationState&) {}));
}

}  // namespace
