// Counts heap allocations across a long per-sample run: there must be none after construction.
#include <gtest/gtest.h>

#include "alloc_counter.hpp"

#include <algorithm>
#include <cstdlib>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/calibration/config_yaml.hpp"
#include "synthetic.hpp"


using namespace bbw::calibration;

TEST(CalibratorAllocation, NoHeapAllocationPerSample) {
  // Both modes, robust mode with every optional effect term (viscous, force delay, backlash,
  // load-dependent friction, load-cell thermal offset) on, and the shipped robust.yaml (its
  // wide element set and larger store, issue 13) with every term on too.
  for (int variant = 0; variant < 4; ++variant) {
    const Mode mode = variant == 1 ? Mode::Paper : Mode::Robust;
    CalibratorConfig c = variant == 3 ? load_config(BBW_SOURCE_DIR "/config/calibrator/robust.yaml") : CalibratorConfig{};
    c.mode = mode;
    if (variant >= 2) {
      c.viscous_friction = true;
      c.force_delay_s = 0.005;
      c.backlash_width_rev = 0.02;
      c.load_friction_gain = 0.5;
      c.load_cell_offset_kN_per_C = 0.01;
    }
    if (variant < 3) {
      c.elements_M = 8;
      c.samples_L = 64;
    }
    c.x_min_rev = 0.5;
    c.x_max_rev = 6.0;
    c.f_max_kN = 40.0;
    test::SyntheticTruth truth;
    truth.delta_rev.assign(8, 0.0);
    thresholds(8, std::min(c.delta_max_rev, 0.4), mode == Mode::Robust, 0.6, truth.delta_rev.data());
    for (double d : truth.delta_rev) truth.k_kN_per_rev.push_back(0.1 / d);
    const auto rec = test::synthetic_recording(truth, 0.03, 9);
    Calibrator cal(c);
    const long before = bbw::test::allocation_count();
    double sink = 0.0;
    for (std::size_t k = 0; k < rec.time_s.size(); ++k) {
      sink += cal.update({rec.time_s[k], rec.position_rev[k], rec.force_kN[k]}).force_kN;
    }
    const long after = bbw::test::allocation_count();
    EXPECT_EQ(after - before, 0) << "variant " << variant << ", mode " << to_string(mode);
    EXPECT_GE(cal.stats().fits_accepted, 8u);  // the run did exercise the cycle-end fits
    EXPECT_TRUE(std::isfinite(sink));
  }
}
