// The sample guard, the fault monitor's rules on synthetic readings, and the last good state.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <random>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/faults/bridged_curve.hpp"
#include "bbw/faults/corner_supervisor.hpp"
#include "bbw/faults/detectors/jump_detector.hpp"
#include "bbw/faults/fault_monitor.hpp"
#include "bbw/faults/last_good.hpp"
#include "bbw/faults/sample_guard.hpp"
#include "bbw/plant/clamp_curve.hpp"
#include "closed_loop.hpp"

using namespace bbw::faults;

namespace {

CornerReading at(std::uint64_t seq, double t, double x = 2.0, double lc = 5.0) {
  CornerReading r;
  r.seq = seq;
  r.time_s = t;
  r.position_rev = x;
  r.force_kN = lc;
  r.motor_current_A = 1.0;
  return r;
}

bbw::calibration::Estimate estimate(double force_kN, double curve_kN) {
  bbw::calibration::Estimate e;
  e.valid = true;
  e.calibrated = true;
  e.force_kN = force_kN;
  e.curve_force_kN = curve_kN;
  return e;
}

// An end-of-line monitor's parameters: the default clamp curve and a key friction of the given
// half-width; stiff keys flip their whole width within about 0.01 rev.
MonitorParams eol_params(double half_width_kN, bool stiff_keys) {
  MonitorParams p;
  p.eol_curve = bbw::plant::ClampCurveParams{};
  bbw::plant::KeyFrictionParams k;
  k.half_width_kN = half_width_kN;
  if (stiff_keys) {
    k.threshold_distribution = bbw::plant::ThresholdDistribution::LogUniform;
    k.threshold_min_rev = 0.002;
    k.threshold_max_rev = 0.005;
  }
  p.eol_key_friction = k;
  p.eol_friction_half_width_kN = half_width_kN;
  return p;
}

// The caliper an end-of-line monitor describes: its clamp curve, its own keys (relaxed at 0) and
// the curve's reference temperature.
struct EolCaliper {
  bbw::plant::ClampCurve curve;
  bbw::plant::KeyFriction keys;
  double T;
  explicit EolCaliper(const MonitorParams& p)
      : curve{*p.eol_curve}, keys{*p.eol_key_friction}, T{p.eol_curve->reference_temperature_C} {
    keys.reset(0.0);
  }
};

// A reading of a live resolver (noise of its quantum) at the curve's reference temperature,
// with the current that holds the load cell's force.
CornerReading live_reading(int n, double t, double x, double speed, double lc, const MonitorParams& p) {
  auto r = at(static_cast<std::uint64_t>(n), t, x + 2e-5 * ((n * 7) % 3), lc);
  r.speed_rev_per_s = speed;
  r.temperature_C = p.eol_curve->reference_temperature_C;
  r.motor_current_A = lc * p.Nm_per_kN / p.torque_per_A_Nm;
  return r;
}

// The calibrator once `calibrated`: its friction estimate and curve at the position, the load
// cell less its friction as the force.
bbw::calibration::Estimate fitted(bool calibrated, double lc_kN, double friction_kN, double curve_kN) {
  bbw::calibration::Estimate e;
  e.valid = true;
  e.calibrated = calibrated;
  e.friction_fitted = calibrated;  // a calibrator's own fits: its states are known
  e.friction_kN = friction_kN;
  e.force_kN = lc_kN - friction_kN;
  e.curve_force_kN = curve_kN;
  return e;
}

// A calibrator before its first fit, started without the caliper's keys: the load cell as it is.
bbw::calibration::Estimate uncalibrated(double lc) {
  bbw::calibration::Estimate e;
  e.valid = true;
  e.calibrated = false;
  e.force_kN = lc;
  return e;
}

// Noiseless synthetic channels repeat exactly, which the frozen rule (a live channel's noise never
// repeats an unquantised value) takes for stuck sensors: tests of the other rules on such
// signals turn it off.
// From sample `from` on, the resolver repeats what it read at `from` (position and speed).
void stick_resolver(CornerReading& r, CornerReading& held, int k, int from) {
  if (k == from) held = r;
  if (k >= from) {
    r.position_rev = held.position_rev;
    r.speed_rev_per_s = held.speed_rev_per_s;
  }
}

MonitorParams noiseless() {
  MonitorParams p;
  p.stuck_frozen_run_factor = 0.0;
  return p;
}

}  // namespace

TEST(SampleGuard, ClassifiesAndCountsEveryKindOfCorruptSample) {
  SampleGuard g(GuardLimits{});
  EXPECT_TRUE(g.check(at(1, 0.001)).usable());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto r = at(2, 0.002);
  r.position_rev = nan;
  EXPECT_EQ(g.check(r).issue, SampleIssue::NonFinite);
  r = at(2, 0.002, 2.0, inf);
  EXPECT_EQ(g.check(r).issue, SampleIssue::NonFinite);
  r = at(2, 0.002, 2.0, 500.0);
  EXPECT_EQ(g.check(r).issue, SampleIssue::OutOfRange);
  r = at(2, 0.002, 42.0);
  EXPECT_EQ(g.check(r).issue, SampleIssue::OutOfRange);
  EXPECT_EQ(g.check(at(1, 0.002)).issue, SampleIssue::Duplicate);
  EXPECT_EQ(g.check(at(0, 0.002)).issue, SampleIssue::SequenceBackwards);
  EXPECT_EQ(g.check(at(2, 0.001)).issue, SampleIssue::TimeBackwards);
  // A dropout: usable, without its load cell.
  const auto c = g.check(at(2, 0.002, 2.0, nan));
  EXPECT_TRUE(c.usable());
  EXPECT_FALSE(c.load_cell_present);
  EXPECT_EQ(g.load_cell_missing(), 1u);
  EXPECT_EQ(g.rejected(), 7u);
  EXPECT_EQ(g.count(SampleIssue::NonFinite), 2u);
  // A forged sample far ahead (sequence or time) is rejected, and the honest stream goes on.
  EXPECT_EQ(g.check(at(2000000, 0.005)).issue, SampleIssue::Jump);
  EXPECT_EQ(g.check(at(3, 1000.0)).issue, SampleIssue::Jump);
  EXPECT_TRUE(g.check(at(3, 0.0025)).usable());
  EXPECT_EQ(g.count(SampleIssue::Jump), 2u);
  // A restarted corner counts from 1 again; its time must still move forward.
  g.rejoin();
  EXPECT_EQ(g.check(at(1, 0.001)).issue, SampleIssue::TimeBackwards);
  EXPECT_TRUE(g.check(at(1, 0.003)).usable());
  EXPECT_EQ(g.check(at(1, 0.004)).issue, SampleIssue::Duplicate);
  // After a lost link the same process goes on: it may jump ahead (the outage's samples never
  // came), but not back nor repeat; the next accepted sample restores the jump limits.
  EXPECT_TRUE(g.check(at(2, 0.004)).usable());
  g.rejoin(false);
  EXPECT_EQ(g.check(at(1, 0.010)).issue, SampleIssue::SequenceBackwards);
  EXPECT_EQ(g.check(at(2, 0.010)).issue, SampleIssue::Duplicate);
  EXPECT_TRUE(g.check(at(2000000, 30.0)).usable());
  EXPECT_EQ(g.check(at(4000000, 31.0)).issue, SampleIssue::Jump);
}

// A load cell the CCU has named faulty: its value out of range (or infinite) is no value, and the
// sample still counts (a drift past -10 kN; tuning seed 1401 run 62). Not named: corrupt.
TEST(SampleGuard, ADiagnosedLoadCellOutOfRangeIsAbsentNotCorrupt) {
  SampleGuard g(GuardLimits{});
  EXPECT_TRUE(g.check(at(1, 0.001)).usable());
  EXPECT_EQ(g.check(at(2, 0.002, 2.0, -13.5)).issue, SampleIssue::OutOfRange);
  const auto c = g.check(at(2, 0.002, 2.0, -13.5), true);
  EXPECT_TRUE(c.usable());
  EXPECT_FALSE(c.load_cell_present);
  const auto i = g.check(at(3, 0.003, 2.0, std::numeric_limits<double>::infinity()), true);
  EXPECT_TRUE(i.usable());
  EXPECT_FALSE(i.load_cell_present);
  EXPECT_TRUE(g.check(at(4, 0.004, 2.0, 5.0), true).load_cell_present);  // in range: a value
  EXPECT_EQ(g.load_cell_ignored(), 2u);
  EXPECT_EQ(g.load_cell_missing(), 0u);
  EXPECT_EQ(g.rejected(), 1u);
  // The rest of the sample is still checked.
  EXPECT_EQ(g.check(at(5, 0.005, 42.0, -13.5), true).issue, SampleIssue::OutOfRange);
}

TEST(FaultMonitor, DefaultParametersAreValidAndInvalidOnesNameTheField) {
  EXPECT_NO_THROW(MonitorParams{}.validate());
  MonitorParams p;
  p.uncalibrated_residual_threshold_kN = 0.1;
  try {
    p.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("uncalibrated_residual_threshold_kN"), std::string::npos);
  }
  EXPECT_THROW(FaultMonitor(MonitorParams{}, Target::CCU), std::invalid_argument);
}

TEST(FaultMonitor, AResidualMustPersistAndIsIsolatedToTheLoadCellWithoutAResolverJump) {
  MonitorParams p = noiseless();
  FaultMonitor m(p, Target::FR);
  SampleGuard g(p.guard);
  std::uint64_t seq = 0;
  double t = 0.0;
  auto feed = [&](double residual_kN, double x) {
    ++seq;
    t += 0.001;
    auto r = at(seq, t, x, 10.0 + residual_kN);
    const auto e = estimate(10.0 + residual_kN, 10.0);
    m.update(r, g.check(r), &e, e.force_kN, t);
  };
  for (int k = 0; k < 100; ++k) feed(0.1, 3.0);
  // A short excursion (shorter than residual_persist_s) is not a fault.
  for (int k = 0; k < 15; ++k) feed(1.0, 3.0);
  for (int k = 0; k < 50; ++k) feed(0.1, 3.0);
  EXPECT_TRUE(m.ok(Part::LoadCell));
  const double onset = t + 0.001;
  for (int k = 0; k < 40; ++k) feed(1.0, 3.0);
  const auto& d = m.diagnosis(Part::LoadCell);
  ASSERT_TRUE(d.present);
  EXPECT_EQ(d.finding, Finding::LoadCellOffset);
  EXPECT_NEAR(d.onset_s, onset, 1e-9);
  EXPECT_NEAR(d.detected_s - d.onset_s, p.residual_persist_s, 1.5e-3);
  EXPECT_TRUE(m.ok(Part::Resolver));
}

TEST(FaultMonitor, OutsideTheFittedRangeTheResidualIsNotJudged) {
  MonitorParams p = noiseless();
  FaultMonitor m(p, Target::FR);
  m.set_curve_range(2.0, 4.0);
  SampleGuard g(p.guard);
  for (int k = 1; k < 200; ++k) {
    auto r = at(static_cast<std::uint64_t>(k), 0.001 * k, 5.0, 20.0);
    const auto e = estimate(20.0, 17.0);
    m.update(r, g.check(r), &e, e.force_kN, r.time_s);
  }
  EXPECT_TRUE(m.ok(Part::LoadCell));
  EXPECT_TRUE(std::isnan(m.last_residual_kN()));
}

TEST(FaultMonitor, AResolverJumpIsAnOffsetUnlessItIsUndone) {
  MonitorParams p = noiseless();
  SampleGuard g(p.guard);
  FaultMonitor glitch(p, Target::FL), offset(p, Target::FL);
  for (int k = 1; k < 100; ++k) {
    const double t = 0.001 * k;
    const double x_glitch = k == 50 ? 2.1 : 2.0;
    const double x_offset = k >= 50 ? 2.1 : 2.0;
    auto a = at(static_cast<std::uint64_t>(k), t, x_glitch);
    a.speed_rev_per_s = 0.0;
    auto b = at(static_cast<std::uint64_t>(k), t, x_offset);
    b.speed_rev_per_s = 0.0;
    SampleCheck ok;
    glitch.update(a, ok, nullptr, 5.0, t);
    offset.update(b, ok, nullptr, 5.0, t);
  }
  EXPECT_TRUE(glitch.ok(Part::Resolver));
  ASSERT_FALSE(offset.ok(Part::Resolver));
  EXPECT_EQ(offset.diagnosis(Part::Resolver).finding, Finding::ResolverOffset);
  EXPECT_NEAR(offset.diagnosis(Part::Resolver).onset_s, 0.050, 1e-9);
}

// A position step is explained anywhere between what the two measured speeds give: a drive that
// seizes at its 25 rev/s limit stops within one sample (its step 0.024 rev, the trapezoid's
// prediction 0.0125 rev: a seized drive was named resolver_offset, stress seed 1406 run 360); a
// 0.02 rev offset while it runs at 25 rev/s is still one.
TEST(FaultMonitor, ARotorThatStopsWithinOneSampleIsNoResolverJump) {
  auto run = [](bool seize, double offset_rev) {
    MonitorParams p = noiseless();
    FaultMonitor m(p, Target::RR);
    SampleCheck ok;
    double x = 2.0;
    for (int k = 1; k < 100; ++k) {
      const double t = 0.001 * k;
      double v = 25.0;
      if (seize && k == 50) {
        x += 0.024;  // stopped at the end of the sample
        v = 0.0;
      } else if (seize && k > 50) {
        v = 0.0;
      } else {
        x += 0.025;
      }
      auto r = at(static_cast<std::uint64_t>(k), t, x + (k >= 50 ? offset_rev : 0.0));
      r.speed_rev_per_s = v;
      m.update(r, ok, nullptr, 5.0, t);
    }
    return m.diagnosis(Part::Resolver);
  };
  EXPECT_FALSE(run(true, 0.0).present) << to_string(run(true, 0.0).finding);
  EXPECT_EQ(run(false, 0.02).finding, Finding::ResolverOffset);
  EXPECT_EQ(run(false, -0.02).finding, Finding::ResolverOffset);
}

TEST(FaultMonitor, StuckChannelsNeedTheOtherChannelToMove) {
  MonitorParams p = noiseless();
  SampleCheck ok;
  FaultMonitor parked(p, Target::RL), moving(p, Target::RL), resolver(p, Target::RL);
  for (int k = 1; k < 100; ++k) {
    const double t = 0.001 * k;
    parked.update(at(k, t, 2.0, 7.0), ok, nullptr, 7.0, t);               // nothing moves: no finding
    moving.update(at(k, t, 2.0 + 0.01 * k, 7.0), ok, nullptr, 7.0, t);    // load cell frozen, position moves
    resolver.update(at(k, t, 2.0, 7.0 + 0.1 * k), ok, nullptr, 7.0, t);   // position frozen, load moves
  }
  EXPECT_EQ(parked.diagnosis(Part::LoadCell).present || parked.diagnosis(Part::Resolver).present, false);
  EXPECT_EQ(moving.diagnosis(Part::LoadCell).finding, Finding::LoadCellStuck);
  EXPECT_EQ(resolver.diagnosis(Part::Resolver).finding, Finding::ResolverStuck);
}

// Frozen at any motion (issue 14): a live load cell's noise never repeats its (unquantised)
// value, nor does the resolver's speed, so 20 exact repeats are a stuck sensor even in a hold,
// where the motion rule above waits for the next apply or release (tuning seed 1403: stuck
// load cells found 250-700 ms after the onset in hard stops). A live quantised position repeats
// by itself (noise about its quantum); with its speed live that is no finding, nor is a sensor
// whose own healthy runs of repeats were long (the run factor: a coarsely quantised load cell).
TEST(FaultMonitor, AChannelFrozenInAHoldIsStuck) {
  auto run = [](int lc_stuck_from, int resolver_stuck_from, double lc_quantum_kN) {
    MonitorParams p;
    SampleCheck ok;
    FaultMonitor m(p, Target::FL);
    std::mt19937_64 rng(3);
    std::normal_distribution<double> n01(0.0, 1.0);
    CornerReading held{};
    for (int k = 1; k < 2000; ++k) {
      const double t = 0.001 * k;
      double lc = 20.0 + 0.03 * n01(rng);
      if (lc_quantum_kN > 0.0) lc = std::round(lc / lc_quantum_kN) * lc_quantum_kN;
      auto r = at(k, t, std::round((4.6 + 2e-5 * n01(rng)) / 2e-5) * 2e-5, lc);
      r.speed_rev_per_s = 0.005 * n01(rng);
      r.motor_current_A = lc * p.Nm_per_kN / p.torque_per_A_Nm;
      if (k == lc_stuck_from) held = r;
      if (k >= lc_stuck_from) r.force_kN = held.force_kN;
      stick_resolver(r, held, k, resolver_stuck_from);
      m.update(r, ok, nullptr, r.force_kN, t);
    }
    return m;
  };
  const auto healthy = run(1 << 30, 1 << 30, 0.0);
  EXPECT_TRUE(healthy.ok(Part::LoadCell) && healthy.ok(Part::Resolver));
  const auto lc = run(1000, 1 << 30, 0.0);
  EXPECT_EQ(lc.diagnosis(Part::LoadCell).finding, Finding::LoadCellStuck);
  EXPECT_LT(lc.diagnosis(Part::LoadCell).detected_s, 1.025);
  EXPECT_TRUE(lc.ok(Part::Resolver));
  const auto res = run(1 << 30, 1000, 0.0);
  EXPECT_EQ(res.diagnosis(Part::Resolver).finding, Finding::ResolverStuck);
  EXPECT_LT(res.diagnosis(Part::Resolver).detected_s, 1.025);
  EXPECT_TRUE(res.ok(Part::LoadCell));
  // A load cell quantised at 3x its noise repeats by itself: no finding while healthy.
  const auto coarse = run(1 << 30, 1 << 30, 0.09);
  EXPECT_TRUE(coarse.ok(Part::LoadCell)) << to_string(coarse.diagnosis(Part::LoadCell).finding);
}

// Once the resolver is diagnosed there is no residual (it needs the position), so the noise
// rule had nothing to count and a noise burst after a stuck resolver went unseen (issue 14: 4 of
// tune_b's 5 noise-burst misses). The load cell's own second difference takes over: a 0.25 kN
// RMS burst (the stated limit) on a force that moves like a 10 Hz ABS modulation is found within
// 0.1 s; the same load cell at 0.05 kN RMS for 20 s is not.
TEST(FaultMonitor, ANoisyLoadCellIsFoundAfterTheResolverIsDiagnosed) {
  auto run = [](double healthy_rms_kN, double burst_rms_kN, double burst_at_s, double until_s, double learned_factor) {
    MonitorParams p;
    p.noise_learned_factor = learned_factor;
    SampleCheck ok;
    FaultMonitor m(p, Target::RL);
    std::mt19937_64 rng(11);
    std::normal_distribution<double> n01(0.0, 1.0);
    CornerReading held{};
    for (int k = 1; 0.001 * k <= until_s + 1e-12; ++k) {
      const double t = 0.001 * k;
      const double w = 2.0 * 3.14159265358979 * 10.0;
      const double force_kN = 15.0 + 5.0 * std::sin(w * t);  // 20 kN/rev: the position moves with it
      const double rms_kN = t >= burst_at_s ? burst_rms_kN : healthy_rms_kN;
      auto r = at(k, t, std::round((4.0 + 0.05 * (force_kN - 15.0) + 2e-5 * n01(rng)) / 2e-5) * 2e-5,
                  force_kN + rms_kN * n01(rng));
      r.speed_rev_per_s = 0.25 * w * std::cos(w * t) + 0.005 * n01(rng);
      r.motor_current_A = 0.0;
      stick_resolver(r, held, k, 500);  // the resolver sticks at 0.5 s
      m.update(r, ok, nullptr, r.force_kN, t);
    }
    return m;
  };
  const double factor = MonitorParams{}.noise_learned_factor;
  const auto burst = run(0.05, 0.25, 1.0, 1.5, factor);
  ASSERT_EQ(burst.diagnosis(Part::Resolver).finding, Finding::ResolverStuck);
  EXPECT_EQ(burst.diagnosis(Part::LoadCell).finding, Finding::LoadCellNoisy)
      << to_string(burst.diagnosis(Part::LoadCell).finding) << " at " << burst.diagnosis(Part::LoadCell).detected_s;
  EXPECT_LT(burst.diagnosis(Part::LoadCell).detected_s, 1.1);
  const auto healthy = run(0.05, 0.05, 0.0, 20.0, factor);
  EXPECT_EQ(healthy.diagnosis(Part::Resolver).finding, Finding::ResolverStuck);
  EXPECT_TRUE(healthy.ok(Part::LoadCell))
      << to_string(healthy.diagnosis(Part::LoadCell).finding) << " at " << healthy.diagnosis(Part::LoadCell).detected_s;
  // A healthy load cell at 0.08 kN RMS (the stress population's noisiest; its second
  // differences cross the fixed 0.35 kN in 7 % of samples) is judged by the level learnt from
  // its own second differences (fourteenth session: 18 findings after a resolver fault on the
  // stress seed); with that learning off it is named noisy. A 0.4 kN burst on it is still found.
  const auto noisy_healthy = run(0.08, 0.08, 0.0, 20.0, factor);
  EXPECT_TRUE(noisy_healthy.ok(Part::LoadCell))
      << to_string(noisy_healthy.diagnosis(Part::LoadCell).finding) << " at " << noisy_healthy.diagnosis(Part::LoadCell).detected_s;
  const auto unlearnt = run(0.08, 0.08, 0.0, 20.0, 0.0);
  EXPECT_EQ(unlearnt.diagnosis(Part::LoadCell).finding, Finding::LoadCellNoisy);
  const auto burst_on_noisy = run(0.08, 0.4, 5.0, 5.5, factor);
  EXPECT_EQ(burst_on_noisy.diagnosis(Part::LoadCell).finding, Finding::LoadCellNoisy)
      << to_string(burst_on_noisy.diagnosis(Part::LoadCell).finding);
  EXPECT_GE(burst_on_noisy.diagnosis(Part::LoadCell).detected_s, 5.0);
  EXPECT_LT(burst_on_noisy.diagnosis(Part::LoadCell).detected_s, 5.1);
}

TEST(FaultMonitor, DropoutNeedsConsecutiveMissingValues) {
  MonitorParams p;
  FaultMonitor m(p, Target::FL);
  SampleCheck missing;
  missing.load_cell_present = false;
  SampleCheck ok;
  for (int k = 1; k < 60; ++k) {
    const bool gap = (k % 5 == 0) || (k >= 40 && k < 40 + p.dropout_samples);
    m.update(at(k, 0.001 * k), gap ? missing : ok, nullptr, 5.0, 0.001 * k);
    if (k < 40 + p.dropout_samples - 1) {
      ASSERT_TRUE(m.ok(Part::LoadCell)) << k;
    }
  }
  EXPECT_EQ(m.diagnosis(Part::LoadCell).finding, Finding::LoadCellMissing);
  EXPECT_NEAR(m.diagnosis(Part::LoadCell).onset_s, 0.040, 1e-9);
}

TEST(FaultMonitor, DeadlineLivelinessAndRejoin) {
  MonitorParams p;
  FaultMonitor m(p, Target::RR);
  SampleCheck ok;
  m.update(at(1, 0.001), ok, nullptr, 5.0, 0.001);
  m.tick(0.001 + p.deadline_s * 0.9);
  EXPECT_TRUE(m.ok(Part::Network));
  m.tick(0.001 + p.deadline_s * 1.1);
  EXPECT_EQ(m.diagnosis(Part::Network).finding, Finding::LinkLost);
  m.on_link_event(LinkEvent::LivelinessLost, 0.03);
  EXPECT_TRUE(m.ok(Part::Network));  // the process is named instead of the link
  EXPECT_EQ(m.diagnosis(Part::Process).finding, Finding::ProcessLost);
  EXPECT_NEAR(m.diagnosis(Part::Process).onset_s, 0.001, 1e-12);
  EXPECT_TRUE(m.process_was_lost());
  m.update(at(1, 0.5), ok, nullptr, 5.0, 0.5);
  EXPECT_TRUE(m.ok(Part::Process));
  EXPECT_TRUE(m.diagnosis(Part::Process).present);
  EXPECT_TRUE(m.take_rejoin());
  EXPECT_FALSE(m.take_rejoin());
}

// Lockstep: blocks arrive at the period ends and the CCU ticks after each period's arrivals. Three
// periods without a block (an arrival gap of 20 ms, a 22 ms delay's) reach the 15 ms deadline at
// the third period's tick; two (a gap of 15 ms) do not, the late block arrives before that tick.
TEST(FaultMonitor, InLockstepThreeMissingPeriodsAreALostLinkAndTwoAreNot) {
  auto run = [](int missing_periods) {
    MonitorParams p;
    FaultMonitor m(p, Target::RL);
    SampleCheck ok;
    for (int k = 1; k <= 30; ++k) {
      const double t = 0.005 * k;
      if (k <= 10 || k > 10 + missing_periods) m.update(at(static_cast<std::uint64_t>(k), t), ok, nullptr, 5.0, t);
      m.tick(t);
    }
    return m.diagnosis(Part::Network);
  };
  const Diagnosis three = run(3);
  ASSERT_TRUE(three.present);
  EXPECT_EQ(three.finding, Finding::LinkLost);
  EXPECT_NEAR(three.onset_s, 0.050, 1e-12);
  EXPECT_NEAR(three.detected_s, 0.065, 1e-12);
  EXPECT_FALSE(run(2).present);
}

// A delay loses no sample: a corner whose first sample after the outage continues its sequence
// keeps every detector's state (tuning seed 1401 run 289: the end-of-line friction model's reset
// at a delayed corner's rejoin made the reversal 1 ms later look like a noisy load cell). Seen
// through the frozen rule: a load cell frozen for 11 samples before a 20 ms outage and 10 after
// is stuck when the sequence continues, and not when it starts again (a new incarnation, whose
// first samples say nothing of the old one's).
TEST(FaultMonitor, ADelayedCornerKeepsItsDetectorsAcrossTheOutage) {
  auto run = [](bool continues) {
    MonitorParams p;
    FaultMonitor m(p, Target::FR);
    SampleCheck ok;
    std::mt19937_64 rng(5);
    std::normal_distribution<double> n01(0.0, 1.0);
    double frozen_kN = 0.0;
    for (int k = 1; k <= 110; ++k) {
      const double t = 0.001 * k;
      const bool late = k > 100;  // held back by the outage, delivered 20 ms late
      auto r = at(static_cast<std::uint64_t>(continues || !late ? k : k - 100), t, 3.0 + 2e-4 * k, 10.0 + 0.03 * n01(rng));
      r.speed_rev_per_s = 0.2 + 0.005 * n01(rng);
      if (k == 90) frozen_kN = r.force_kN;
      if (k >= 90) r.force_kN = frozen_kN;
      if (k == 101) m.tick(0.121);  // the outage: nothing for 20 ms
      m.update(r, ok, nullptr, r.force_kN, late ? t + 0.020 : t);
    }
    return m;
  };
  const FaultMonitor delayed = run(true);
  EXPECT_TRUE(delayed.diagnosis(Part::Network).present);
  EXPECT_EQ(delayed.diagnosis(Part::LoadCell).finding, Finding::LoadCellStuck);
  EXPECT_TRUE(run(false).ok(Part::LoadCell));
}

// A restarted process (new incarnation) that rejoins before the participant lease ran out: the
// open link outage is renamed the process's death, from the link's onset; a process already
// named is left as it was.
TEST(FaultMonitor, ARestartedProcessNamesTheOutageAsTheProcesssDeath) {
  MonitorParams p;
  FaultMonitor m(p, Target::RR);
  SampleCheck ok;
  m.update(at(1, 0.001), ok, nullptr, 5.0, 0.001);
  m.tick(0.001 + p.deadline_s * 1.1);
  ASSERT_EQ(m.diagnosis(Part::Network).finding, Finding::LinkLost);
  m.on_link_event(LinkEvent::Restarted, 0.5);
  EXPECT_TRUE(m.ok(Part::Network));
  EXPECT_EQ(m.diagnosis(Part::Process).finding, Finding::ProcessLost);
  EXPECT_NEAR(m.diagnosis(Part::Process).onset_s, 0.001, 1e-12);
  EXPECT_NEAR(m.diagnosis(Part::Process).detected_s, 0.5, 1e-12);
  EXPECT_TRUE(m.process_was_lost());
  m.update(at(1, 0.5), ok, nullptr, 5.0, 0.5);
  EXPECT_TRUE(m.ok(Part::Process));
  EXPECT_TRUE(m.take_rejoin());

  // Already named by its lease: the restart changes nothing.
  FaultMonitor n(p, Target::FL);
  n.update(at(1, 0.001), ok, nullptr, 5.0, 0.001);
  n.on_link_event(LinkEvent::LivelinessLost, 2.0);
  const Diagnosis before = n.diagnosis(Part::Process);
  n.on_link_event(LinkEvent::Restarted, 2.5);
  EXPECT_EQ(n.diagnosis(Part::Process).detected_s, before.detected_s);
  EXPECT_EQ(n.diagnosis(Part::Process).finding, Finding::ProcessLost);
}

TEST(FaultMonitor, TorqueBalanceSeparatesPartialAndTotalLoss) {
  MonitorParams p = noiseless();
  SampleCheck ok;
  auto run = [&](double fraction) {
    FaultMonitor m(p, Target::FL);
    for (int k = 1; k < 200; ++k) {
      auto r = at(k, 0.001 * k, 4.0, 20.0);
      r.speed_rev_per_s = 0.0;
      r.motor_current_A = 20.0 * p.Nm_per_kN / (p.torque_per_A_Nm * fraction);
      m.update(r, ok, nullptr, 20.0, r.time_s);
    }
    return m.diagnosis(Part::Actuator);
  };
  EXPECT_FALSE(run(0.9).present);
  EXPECT_EQ(run(0.4).finding, Finding::ActuatorTorqueLoss);
  EXPECT_EQ(run(0.1).finding, Finding::ActuatorLost);
}

// Applying at speed the drive's friction is known in sign and size, so the balance holds in motion
// too: a motor that makes 40 % of its torque is named a torque loss during a 1.5 rev/s apply at 5
// kN (below the standstill check's minimum load), a healthy one is not, nor a load cell 2 kN low,
// nor the same loss while releasing (the load back-drives the screw); with the moving check off
// it waits for a hold at a higher load.
namespace {

// The position (0.5-10 rev) where `curve` makes `force_kN` at `temperature_C`, unworn (bisection).
double position_on(const bbw::plant::ClampCurve& curve, double temperature_C, double force_kN) {
  double lo = 0.5, hi = 10.0;
  for (int i = 0; i < 60; ++i) ((curve.force_kN(0.5 * (lo + hi), temperature_C, 0.0) < force_kN) ? lo : hi) = 0.5 * (lo + hi);
  return 0.5 * (lo + hi);
}

// A drive moving at `speed_rev_per_s` from `x0_rev` for 0.2 s on a 2 kN/rev slope (no curve), its
// true load from `true_kN`, its load cell from `lc_kN`, with the current a drive making `fraction`
// of its torque needs; the actuator's diagnosis (the sensors must stay trusted).
Diagnosis drive_at_speed(const MonitorParams& p, double x0_rev, double fraction, double speed_rev_per_s, double true_kN,
                         double lc_kN) {
  SampleCheck ok;
  FaultMonitor m(p, Target::FL);
  const double friction_Nm = bbw::plant::drive_friction_Nm(p.drive, speed_rev_per_s);
  for (int k = 1; k < 200; ++k) {
    const double t = 0.001 * k;
    const double rise_kN = 2.0 * speed_rev_per_s * t;  // 2 kN/rev
    auto r = at(k, t, x0_rev + speed_rev_per_s * t, lc_kN + rise_kN);
    r.speed_rev_per_s = speed_rev_per_s + (k % 2 == 0 ? 1e-4 : -1e-4);  // a real speed never repeats exactly
    r.motor_current_A = ((true_kN + rise_kN) * p.Nm_per_kN + friction_Nm) / (p.torque_per_A_Nm * fraction);
    m.update(r, ok, nullptr, r.force_kN, t);
  }
  EXPECT_TRUE(m.ok(Part::LoadCell) && m.ok(Part::Resolver));
  return m.diagnosis(Part::Actuator);
}

}  // namespace

TEST(FaultMonitor, ATorqueLossIsNamedDuringAnApplyBelowTheHoldChecksLoad) {
  MonitorParams base = noiseless();
  auto run = [](const MonitorParams& p, double fraction, double speed_rev_per_s, double true_kN, double lc_kN) {
    return drive_at_speed(p, 2.0, fraction, speed_rev_per_s, true_kN, lc_kN);
  };
  ASSERT_LT(5.0, base.torque_check_min_load_kN);
  ASSERT_GE(5.0, base.torque_check_moving_min_load_kN);
  EXPECT_FALSE(run(base, 1.0, 1.5, 5.0, 5.0).present);
  EXPECT_EQ(run(base, 0.4, 1.5, 5.0, 5.0).finding, Finding::ActuatorTorqueLoss);
  EXPECT_FALSE(run(base, 1.0, 1.5, 7.0, 5.0).present);   // the load cell 2 kN low
  MonitorParams no_braking = base;
  no_braking.torque_loss_braking_threshold = 0.0;
  EXPECT_FALSE(run(no_braking, 0.4, -1.5, 5.0, 5.0).present);  // releasing (the braking rule below)
  MonitorParams off = base;
  off.torque_check_moving_min_speed_rev_per_s = 0.0;
  EXPECT_FALSE(run(off, 0.4, 1.5, 5.0, 5.0).present);
}

// Releasing slowly under load the motor holds the screw back against the load less the drive's
// friction; a weaker motor needs proportionally more current for it (twentieth session, tuning
// seed 1406 run 112: a 59 % loss in a slow release at 7 kN, found only after it had ended).
TEST(FaultMonitor, ATorqueLossIsNamedWhileTheMotorHoldsBackARelease) {
  MonitorParams base = noiseless();
  auto run = [](const MonitorParams& p, double fraction, double speed_rev_per_s, double true_kN, double lc_kN) {
    return drive_at_speed(p, 3.0, fraction, speed_rev_per_s, true_kN, lc_kN);
  };
  ASSERT_GT(0.0, bbw::plant::drive_friction_Nm(base.drive, -1.5));  // the friction helps the motor hold back
  EXPECT_FALSE(run(base, 1.0, -1.5, 7.0, 7.0).present);
  const Diagnosis d = run(base, 0.4, -1.5, 7.0, 7.0);
  ASSERT_TRUE(d.present);
  EXPECT_EQ(d.finding, Finding::ActuatorTorqueLoss);  // not lost: 0.4 of the torque is there
  EXPECT_FALSE(run(base, 0.4, -1.5, 3.0, 3.0).present);  // below check_moving_min_load_kN
  EXPECT_FALSE(run(base, 0.4, -0.3, 7.0, 7.0).present);  // slower than check_moving_min_speed_rev_per_s
  EXPECT_FALSE(run(base, 1.0, -1.5, 7.0, 8.0).present);  // the load cell 1 kN high
  MonitorParams off = base;
  off.torque_loss_braking_threshold = 0.0;
  EXPECT_FALSE(run(off, 0.4, -1.5, 7.0, 7.0).present);
}

// Over-application: told to release (command 0) a brake that keeps 10 kN and does not move back
// is named actuator_not_releasing after tracking_persist_s past the point where the force stands
// above the commanded response by the tracking threshold; one that moves back (releasing, if
// slowly) or that holds what it is told is not.
TEST(FaultMonitor, ABrakeThatDoesNotReleaseIsNamedAndOneThatMovesBackIsNot) {
  MonitorParams p = noiseless();
  SampleCheck ok;
  auto run = [&](double command_kN, double speed_rev_per_s, double until_s) {
    FaultMonitor m(p, Target::FL);
    for (int k = 1; 0.001 * k <= until_s + 1e-12; ++k) {
      auto r = at(k, 0.001 * k, 4.0, 10.0);
      r.speed_rev_per_s = speed_rev_per_s;
      r.motor_current_A = 10.0 * p.Nm_per_kN / p.torque_per_A_Nm;  // the torque the load needs
      r.force_command_kN = command_kN;
      m.update(r, ok, nullptr, 10.0, r.time_s);
    }
    return m.diagnosis(Part::Actuator);
  };
  // The model falls below 10 - 3 kN at 0.1 s * ln(10/7) = 35.7 ms; confirmed 200 ms later.
  EXPECT_FALSE(run(0.0, 0.0, 0.230).present);
  const Diagnosis d = run(0.0, 0.0, 0.5);
  ASSERT_TRUE(d.present);
  EXPECT_EQ(d.finding, Finding::ActuatorNotReleasing);
  EXPECT_NEAR(d.onset_s, 0.036, 0.0015);
  EXPECT_NEAR(d.detected_s, 0.236, 0.0015);
  EXPECT_EQ(part_of(d.finding), Part::Actuator);
  EXPECT_FALSE(run(0.0, -0.6, 1.0).present);  // moving back faster than 0.5 rev/s: releasing
  EXPECT_FALSE(run(10.0, 0.0, 1.0).present);  // holds what it is told
  EXPECT_FALSE(run(8.0, 0.0, 1.0).present);   // 2 kN over: within the 3 kN threshold
}

// A released brake told 37 kN at once (a corner back from a link silence in a hard stop, tune_b
// seed 1403 run 752) applies at its 25 rev/s limit: 8 rev take 0.32 s, longer than the tracking
// model's 0.1 s time constant allows, and the force stays more than 30 % of the command below the
// model for 0.22 s. A drive at full speed towards its command (tracking.full_speed_fraction of
// the corners' speed limit) holds the model at its force: nothing named. Without that, it is
// actuator_tracking; and a drive that stops halfway is still named, 0.2 s after the model passes it.
TEST(FaultMonitor, AnApplyAtTheDrivesSpeedLimitIsNotATrackingFault) {
  auto run = [](double fraction, double stop_rev) {
    MonitorParams p = noiseless();
    p.drive_max_speed_rev_per_s = 25.0;
    p.tracking_full_speed_fraction = fraction;
    SampleCheck ok;
    FaultMonitor m(p, Target::FL);
    double x = 0.0, speed = 0.0;
    const double accel = 2500.0;  // rev/s^2: 10 ms to the limit
    for (int k = 1; k <= 1000; ++k) {
      const double t = 0.001 * k;
      const double target = std::min(8.0, stop_rev);
      const double v_next = t > 0.1 ? std::min({25.0, speed + 0.001 * accel, std::sqrt(2.0 * accel * std::max(0.0, target - x))}) : 0.0;
      const double a = (v_next - speed) / 0.001;
      speed = v_next;
      x += 0.001 * speed;
      const double force_kN = 37.0 * std::pow(std::min(x, 8.0) / 8.0, 3);
      auto r = at(k, t, x, force_kN);
      r.speed_rev_per_s = speed;
      r.motor_current_A = (force_kN * p.Nm_per_kN + p.inertia_kg_m2 * 2.0 * M_PI * a) / p.torque_per_A_Nm;
      r.force_command_kN = t > 0.1 ? 37.0 : 0.0;
      m.update(r, ok, nullptr, force_kN, t);
    }
    return m.diagnosis(Part::Actuator);
  };
  const Diagnosis healthy = run(0.8, 100.0);
  EXPECT_FALSE(healthy.present) << to_string(healthy.finding) << " at " << healthy.detected_s;
  const Diagnosis without = run(0.0, 100.0);
  EXPECT_EQ(without.finding, Finding::ActuatorTracking);
  const Diagnosis stopped = run(0.8, 5.0);
  EXPECT_EQ(stopped.finding, Finding::ActuatorTracking);
  EXPECT_LT(stopped.detected_s, 0.6);
}

// The corner's loop holds its load cell at the command, so a healthy clamp force stands off the
// command by the key friction (stress population, 2026-11-26: a caliper with 2.7-3 kN of key
// friction held its clamp force 3 kN above a falling command and was named not releasing). The
// calibrated friction explains that part; a load cell that stays up with the force does not.
TEST(FaultMonitor, AnExcessTheCalibratedKeyFrictionExplainsIsNotABrakeThatDoesNotRelease) {
  MonitorParams p = noiseless();
  SampleCheck ok;
  auto run = [&](double lc_kN, bool calibrated) {
    FaultMonitor m(p, Target::FL);
    for (int k = 1; k <= 800; ++k) {
      auto r = at(k, 0.001 * k, 4.0, k == 1 ? 10.0 : lc_kN);
      r.force_command_kN = k == 1 ? 10.0 : 6.5;  // told to come down from 10 to 6.5 kN
      // The clamp force stays at 10 kN: with the load cell at 6.5 kN the keys hold 3.5 kN
      // (friction -3.5 kN); with it at 10 kN they hold nothing.
      const auto e = fitted(calibrated, r.force_kN, r.force_kN - 10.0, 10.0);
      m.update(r, ok, &e, e.force_kN, r.time_s);
    }
    return m.diagnosis(Part::Actuator);
  };
  EXPECT_FALSE(run(6.5, true).present);  // the load cell came down to the command: released
  const Diagnosis seized = run(10.0, true);  // the load cell stayed up with the force: 3.5 kN over
  ASSERT_TRUE(seized.present);
  EXPECT_EQ(seized.finding, Finding::ActuatorNotReleasing);
  // Before a fit the friction the estimate took out counts too (a calibrator started from the
  // caliper's end-of-line keys takes it out from the first sample: tracking.friction_as_subtracted).
  EXPECT_FALSE(run(6.5, false).present);
  // Counting only fitted friction, the 3.5 kN excess counts as the brake's.
  p.tracking_friction_as_subtracted = false;
  const Diagnosis uncalibrated = run(6.5, false);
  ASSERT_TRUE(uncalibrated.present);
  EXPECT_EQ(uncalibrated.finding, Finding::ActuatorNotReleasing);
}

// A restarted calibrator (a corner back from a lost link) has the fitted K_i of the snapshot it
// restarted from before a fit of its own: once its states are known (Estimate::friction_fitted),
// its friction counts (tracking.friction_after_restart); without the rule, only after its own fit.
TEST(FaultMonitor, ARestartedCalibratorsFittedFrictionExplainsAnExcess) {
  MonitorParams p = noiseless();
  p.tracking_friction_as_subtracted = false;  // (the rule on its own: with it, any friction taken out counts)
  SampleCheck ok;
  auto run = [&](bool friction_fitted) {
    FaultMonitor m(p, Target::FL);
    for (int k = 1; k <= 800; ++k) {
      auto r = at(k, 0.001 * k, 4.0, k == 1 ? 10.0 : 6.5);
      r.force_command_kN = k == 1 ? 10.0 : 6.5;  // the load cell at the command, the keys holding 3.5 kN
      auto e = fitted(false, r.force_kN, r.force_kN - 10.0, 10.0);
      e.friction_fitted = friction_fitted;
      m.update(r, ok, &e, e.force_kN, r.time_s);
    }
    return m.diagnosis(Part::Actuator);
  };
  EXPECT_FALSE(run(true).present);
  EXPECT_EQ(run(false).finding, Finding::ActuatorNotReleasing);  // its states not known yet
  p.tracking_friction_after_restart = false;
  EXPECT_EQ(run(true).finding, Finding::ActuatorNotReleasing);
}

// A part's finding is upgraded to not releasing (and finding_s records when); the first
// detection time stays.
TEST(FaultMonitor, ALostActuatorThatDoesNotReleaseIsUpgraded) {
  MonitorParams p = noiseless();
  SampleCheck ok;
  FaultMonitor m(p, Target::FL);
  int k = 1;
  for (; k < 100; ++k) {  // 10x the current the load needs, no motion: torque lost
    auto r = at(k, 0.001 * k, 4.0, 20.0);
    r.motor_current_A = 10.0 * 20.0 * p.Nm_per_kN / p.torque_per_A_Nm;
    r.force_command_kN = 20.0;
    m.update(r, ok, nullptr, 20.0, r.time_s);
  }
  ASSERT_EQ(m.diagnosis(Part::Actuator).finding, Finding::ActuatorLost);
  const double first_s = m.diagnosis(Part::Actuator).detected_s;
  for (; k < 600; ++k) {  // told to release, holds 20 kN
    auto r = at(k, 0.001 * k, 4.0, 20.0);
    r.motor_current_A = -30.0;
    r.force_command_kN = 0.0;
    m.update(r, ok, nullptr, 20.0, r.time_s);
  }
  const Diagnosis& d = m.diagnosis(Part::Actuator);
  EXPECT_EQ(d.finding, Finding::ActuatorNotReleasing);
  EXPECT_EQ(d.detected_s, first_s);
  EXPECT_GT(d.finding_s, first_s + 0.2);
}

// The curve a lost load cell leaves (bridge_curve): where the fit had data, the fit; beyond, the
// caliper's end-of-line curve's rise from the span's end; before any fit, the end-of-line curve.
// A caliper 0.4 x as stiff as the shipped one, fitted over 3.8-6 rev only (as the faster-driver
// campaign's run 68): the fit extrapolated is kN off at 2 and 7.7 rev, the bridged curve is not.
TEST(BridgeCurve, KeepsTheFitWhereItHadDataAndTheEndOfLineRiseBeyond) {
  bbw::plant::ClampCurveParams soft;
  soft.exp_coefficient_kN *= 0.4;
  soft.linear_kN_per_rev *= 0.4;
  const bbw::plant::ClampCurve eol(soft);
  const double t_C = 72.5;
  auto truth = [&](double x) { return eol.force_kN(x, t_C, 0.0); };
  // The fit: true over its data (a cubic through the truth on 3.8-6 rev), 0.3 kN high there.
  bbw::model::Curve fit = bridge_curve({}, DataSpan{}, eol, t_C, 3.8, 6.0);
  fit.d += 0.3;
  const DataSpan data{3.8, 6.0};
  const double to_rev = eol_position_at(eol, 40.0, t_C, 1.0, 1000.0);  // as the supervisor does
  const bbw::model::Curve bridged = bridge_curve(fit, data, eol, t_C, 1.0, to_rev);
  double worst_fit_outside = 0.0, worst_bridged = 0.0;  // (kN, and kN beyond 3 % of the force)
  for (double x = 1.0; x <= to_rev; x += 0.05) {
    const double expected = truth(x) + 0.3;  // the fit's error carried on, continuous at its ends
    worst_bridged = std::max(worst_bridged, std::abs(bridged.force_kN(x) - expected) - 0.03 * expected);
    if (x < data.lo_rev || x > data.hi_rev) worst_fit_outside = std::max(worst_fit_outside, std::abs(fit.force_kN(x) - truth(x)));
  }
  EXPECT_LT(worst_bridged, 0.4);
  EXPECT_GT(worst_fit_outside, 2.0);
  std::printf("worst error over 1-%.2f rev: bridged %.3f kN + 3 %% of the force (to the fit's level), the fit extrapolated %.3f kN\n",
              to_rev, worst_bridged, worst_fit_outside);
  // No data: the end-of-line curve itself.
  const bbw::model::Curve none = bridge_curve(fit, DataSpan{}, eol, t_C, 1.0, to_rev);
  for (double x = 1.0; x <= to_rev; x += 0.25) EXPECT_NEAR(none.force_kN(x), truth(x), 0.4 + 0.03 * truth(x)) << x;
  EXPECT_THROW(bridge_curve(fit, data, eol, t_C, 6.0, 6.0), std::invalid_argument);
  EXPECT_THROW(bridge_curve(fit, data, eol, t_C, 1.0, std::nan("")), std::invalid_argument);
  // Where the end-of-line curve reaches a force (and the range's end where it does not).
  const double x40 = eol_position_at(eol, 40.0, t_C, 1.0, 1000.0);
  EXPECT_NEAR(truth(x40), 40.0, 1e-4);
  EXPECT_DOUBLE_EQ(eol_position_at(eol, 40.0, t_C, 1.0, 5.0), 5.0);
  EXPECT_DOUBLE_EQ(eol_position_at(eol, 0.0, t_C, 1.0, 5.0), 1.0);
}

TEST(LastGoodCalibration, GivesTheNewestSnapshotBeforeATime) {
  const auto cfg = test::default_options().calibrator;
  bbw::calibration::Calibrator c(cfg);
  LastGoodCalibration g(c);
  EXPECT_FALSE(g.before(10.0).from_fit);
  EXPECT_DOUBLE_EQ(g.before(10.0).curve.d, cfg.initial_curve.d);
  for (int k = 1; k <= 6; ++k) {
    bbw::calibration::Curve curve = cfg.initial_curve;
    curve.d = k;
    c.reset_curve(curve);
    g.push(k, c, DataSpan{1.0, 1.0 + k});
  }
  EXPECT_EQ(g.size(), LastGoodCalibration::kCapacity);
  EXPECT_DOUBLE_EQ(g.before(4.5).curve.d, 4.0);
  EXPECT_DOUBLE_EQ(g.before(4.5).data.hi_rev, 5.0);  // its data span with it
  EXPECT_TRUE(g.before(1.0).data.empty());           // the initial state: no data
  EXPECT_DOUBLE_EQ(g.before(4.0).curve.d, 3.0);
  EXPECT_DOUBLE_EQ(g.newest().curve.d, 6.0);
  EXPECT_FALSE(g.before(2.5).from_fit);  // older than the ring holds: the initial state
}

// A frozen resolver repeats its last speed exactly (a real one carries noise): its acceleration
// reads 0 while the motor works against the loop's reaction, so the torque balance is not checked
// (issue 14: the shipped resolver_stuck scenario's balance named a lost actuator 3 ms before the
// stuck rule named the resolver). The same current with a speed that varies is a lost actuator.
TEST(FaultMonitor, AFrozenResolverSpeedSuspendsTheTorqueBalance) {
  MonitorParams p;
  SampleCheck ok;
  auto run = [&](bool frozen) {
    FaultMonitor m(p, Target::FL);
    for (int k = 1; k < 200; ++k) {
      auto r = at(k, 0.001 * k, 4.0, 20.0);
      r.speed_rev_per_s = frozen ? 6.045 : 6.045 + 1e-3 * (k % 3);
      r.motor_current_A = 20.0 * p.Nm_per_kN / (p.torque_per_A_Nm * 0.1);
      m.update(r, ok, nullptr, 20.0, r.time_s);
    }
    return m.diagnosis(Part::Actuator);
  };
  EXPECT_FALSE(run(true).present);
  EXPECT_EQ(run(false).finding, Finding::ActuatorLost);
}

namespace {

// A monitor with the caliper's end-of-line curve (as CcuCore sets it) and key-friction
// half-width 1 kN, after 20 s of a healthy calibrated residual of 0.05 kN at 3 rev: its learnt
// thresholds are down at the fixed 0.6 kN (issue 14).
struct EolMonitor {
  MonitorParams p = noiseless();
  std::optional<FaultMonitor> m;
  SampleGuard g{MonitorParams{}.guard};
  bbw::plant::ClampCurve eol{bbw::plant::ClampCurveParams{}};
  std::uint64_t seq = 0;
  double t = 0.0;
  EolMonitor() {
    p.eol_curve = bbw::plant::ClampCurveParams{};
    p.eol_friction_half_width_kN = 1.0;
    m.emplace(p, Target::FR);
    m->set_fit_friction_amplitude(1.0);
    for (int k = 0; k < 20000; ++k) feed(0.05);
    m->set_fit_rms(0.05);
  }
  // The load cell reads the curve plus `offset_kN`; the calibrator's friction estimate is 0.
  void feed(double offset_kN) {
    ++seq;
    t += 0.001;
    const double curve_kN = eol.force_kN(3.0, p.eol_curve->reference_temperature_C, 0.0);
    auto r = at(seq, t, 3.0, curve_kN + offset_kN);
    const auto e = estimate(curve_kN + offset_kN, curve_kN);
    m->update(r, g.check(r), &e, e.force_kN, t);
  }
};

}  // namespace

// A fit whose friction amplitude (the most friction it can give) is far from the caliper's
// key-friction width explains the load cell wrongly (tuning runs: up to 5x the width on calipers
// with viscous friction or backlash, friction estimates 4-8 kN on 1-2 kN calipers, and 0 on a 2 kN
// one): the calibrated residual is not used with it, the end-of-line band is.
TEST(FaultMonitor, AFitWithMoreOrLessFrictionThanTheKeysHoldIsJudgedByTheEndOfLineBand) {
  {
    EolMonitor credible;
    EXPECT_TRUE(credible.m->fit_credible());
    for (int k = 0; k < 60; ++k) credible.feed(1.2);
    EXPECT_EQ(credible.m->diagnosis(Part::LoadCell).finding, Finding::LoadCellOffset);
  }
  for (double amplitude_kN : {3.0, 0.2}) {
    EolMonitor wide;
    wide.m->set_fit_friction_amplitude(amplitude_kN);
    EXPECT_FALSE(wide.m->fit_credible()) << amplitude_kN;
    for (int k = 0; k < 60; ++k) wide.feed(1.2);  // within the band: width 1 + 0.5 + 3 %
    EXPECT_TRUE(wide.m->ok(Part::LoadCell)) << amplitude_kN;
    EXPECT_GT(wide.m->last_residual_threshold_kN(), 1.5);
    for (int k = 0; k < 60; ++k) wide.feed(3.0);  // beyond it
    EXPECT_EQ(wide.m->diagnosis(Part::LoadCell).finding, Finding::LoadCellOffset) << amplitude_kN;
  }
  {
    // A credible fit again: the calibrated rule is back.
    EolMonitor again;
    again.m->set_fit_friction_amplitude(3.0);
    again.m->set_fit_friction_amplitude(1.4);
    EXPECT_TRUE(again.m->fit_credible());
    for (int k = 0; k < 60; ++k) again.feed(1.2);
    EXPECT_EQ(again.m->diagnosis(Part::LoadCell).finding, Finding::LoadCellOffset);
  }
}

// Unexplained torque (issue 14): near standstill, at any load, a current whose torque neither the
// load cell's load nor the end-of-line curve's (with its band) explains. A seized drive at 1 kN
// (the loop's current climbs, nothing moves) is a lost actuator within tens of milliseconds; a
// load cell reading 3 kN low at a load the current holds, a gear in its backlash gap (no current
// while the load cell reads the load) and a partial torque loss the loop absorbs are not.
TEST(FaultMonitor, AnUnexplainedTorqueNearStandstillIsALostActuatorAtAnyLoad) {
  MonitorParams p;
  p.eol_curve = bbw::plant::ClampCurveParams{};
  p.eol_friction_half_width_kN = 1.0;
  const bbw::plant::ClampCurve eol{*p.eol_curve};
  const double T = p.eol_curve->reference_temperature_C;
  SampleCheck ok;
  // x: position; load cell; current as a function of the sample index.
  auto run = [&](double x, double lc_kN, auto current_A, int samples) {
    FaultMonitor m(p, Target::RL);
    for (int k = 1; k < samples; ++k) {
      auto r = at(k, 0.001 * k, x, lc_kN);
      r.temperature_C = T;
      r.speed_rev_per_s = 0.004 * ((k % 3) - 1);
      r.motor_current_A = current_A(k);
      m.update(r, ok, nullptr, lc_kN, r.time_s);
    }
    return m;
  };
  const double x1 = 0.8;  // about 1 kN on the default curve
  const double f1 = eol.force_kN(x1, T, 0.0);
  ASSERT_GT(f1, 0.3);
  ASSERT_LT(f1, 2.0);
  const double hold_A = f1 * p.Nm_per_kN / p.torque_per_A_Nm;
  // Seized: the current climbs 100 A/s (the loop's integrator) from the holding current.
  auto seized = run(x1, f1, [&](int k) { return hold_A + 0.1 * k; }, 200);
  EXPECT_EQ(seized.diagnosis(Part::Actuator).finding, Finding::ActuatorLost);
  EXPECT_LT(seized.diagnosis(Part::Actuator).detected_s, 0.15);
  // Healthy hold: the holding current.
  EXPECT_TRUE(run(x1, f1, [&](int) { return hold_A; }, 400).ok(Part::Actuator));
  // A load cell 3 kN low at 6 kN held by its current: the curve explains the current.
  const double x6 = 2.0;
  const double f6 = eol.force_kN(x6, T, 0.0);
  ASSERT_GT(f6, 4.0);
  const double hold6_A = f6 * p.Nm_per_kN / p.torque_per_A_Nm;
  EXPECT_TRUE(run(x6, f6 - 3.0, [&](int) { return hold6_A; }, 400).ok(Part::Actuator));
  // Backlash gap: no current while the load cell reads the load.
  EXPECT_TRUE(run(x6, f6, [&](int) { return 0.0; }, 400).ok(Part::Actuator));
  // A 50 % torque loss the loop absorbs: twice the holding current, steady.
  EXPECT_TRUE(run(x1, f1, [&](int) { return 2.0 * hold_A; }, 400).ok(Part::Actuator));
  // Pulling with the whole current limit the other way while the brake holds (seized in a release).
  auto seized_release = run(x6, f6, [&](int) { return -40.0; }, 200);
  EXPECT_EQ(seized_release.diagnosis(Part::Actuator).finding, Finding::ActuatorLost);
}

// Pulling, a drive that keeps a quarter of its torque or more pulls harder, not in vain
// (twenty-second session, MonitorParams::unexplained_pull_fraction; tuning seed 1401 run 341: a
// 72 % loss braking an apply at 2 kN was named lost). The rotor decelerates at 50 rev/s^2 through
// standstill at 1 kN, which needs about -0.9 Nm: a 72 % loss's current (the need / 0.28) is not
// lost; an 85 % loss's and a dead drive's pull (the current limit) are. Without the fraction the
// 72 % loss is lost too.
TEST(FaultMonitor, APullThatStillBrakesTheRotorIsNotInVain) {
  MonitorParams p = noiseless();
  p.eol_curve = bbw::plant::ClampCurveParams{};
  p.eol_friction_half_width_kN = 1.0;
  const bbw::plant::ClampCurve eol{*p.eol_curve};
  const double T = p.eol_curve->reference_temperature_C;
  const double x0 = 0.8, f_kN = eol.force_kN(x0, T, 0.0);
  constexpr double kTwoPi = 6.283185307179586;
  constexpr double kDecel = 50.0;  // rev/s^2
  const double need_Nm = f_kN * p.Nm_per_kN - p.inertia_kg_m2 * kTwoPi * kDecel;
  ASSERT_LT(need_Nm, -0.5);
  SampleCheck ok;
  // The share of the motor's torque left: the measured current makes the need with it.
  auto run = [&](double left) {
    FaultMonitor m(p, Target::FL);
    for (int k = 1; k <= 80; ++k) {
      const double t = 0.001 * k;
      auto r = at(k, t, x0 + 2.0 * t - 0.5 * kDecel * t * t, f_kN + 0.03 * ((k % 5) - 2));
      r.temperature_C = T;
      r.speed_rev_per_s = 2.0 - kDecel * t;
      r.motor_current_A = (need_Nm + bbw::plant::drive_friction_Nm(p.drive, r.speed_rev_per_s)) / left / p.torque_per_A_Nm;
      r.motor_current_A = std::max(r.motor_current_A, -40.0);
      m.update(r, ok, nullptr, r.force_kN, r.time_s);
    }
    return m.diagnosis(Part::Actuator);
  };
  EXPECT_FALSE(run(1.0).present);
  EXPECT_NE(run(0.28).finding, Finding::ActuatorLost);
  EXPECT_EQ(run(0.15).finding, Finding::ActuatorLost);
  EXPECT_EQ(run(0.01).finding, Finding::ActuatorLost);
  p.unexplained_pull_fraction = false;
  EXPECT_EQ(run(0.28).finding, Finding::ActuatorLost);
}

// Below the moving check's load (issue 14, twentieth session: tuning seed 1403 run 72, a 66 %
// loss in a slow apply named only at 4 kN, 1.035 s after it) the torque-loss rule judges an apply,
// and a release the motor holds back, with the larger plausible load: the end-of-line curve's
// with its band, so a load cell that reads low is not a weak motor. A healthy drive, also one
// whose load cell reads 1.4 kN low in a release, is not named; a 70 % loss applying at 3 kN is
// (an 85 % loss is lost), but not with the low-load check off, nor without the curve (no
// plausible load: the apply is not judged below the moving check's load).
TEST(FaultMonitor, ATorqueLossBelowTheMovingChecksLoadIsJudgedWithTheLargerPlausibleLoad) {
  MonitorParams p = noiseless();
  p.eol_curve = bbw::plant::ClampCurveParams{};
  p.eol_friction_half_width_kN = 1.0;
  const bbw::plant::ClampCurve eol{*p.eol_curve};
  const double T = p.eol_curve->reference_temperature_C;
  auto position_of = [&](double force_kN) { return position_on(eol, T, force_kN); };
  SampleCheck ok;
  // From the position of `true_kN` at `speed`, the load cell `offset_kN` off the curve, the
  // current a drive with `fraction` of its torque needs.
  auto run = [&](const MonitorParams& mp, double fraction, double speed_rev_per_s, double true_kN, double offset_kN) {
    FaultMonitor m(mp, Target::FL);
    const double x0 = position_of(true_kN);
    const double friction_Nm = bbw::plant::drive_friction_Nm(mp.drive, speed_rev_per_s);
    for (int k = 1; k < 150; ++k) {
      const double t = 0.001 * k, x = x0 + speed_rev_per_s * t;
      const double load_kN = eol.force_kN(x, T, 0.0);
      auto r = at(k, t, x, load_kN + offset_kN);
      r.temperature_C = T;
      r.speed_rev_per_s = speed_rev_per_s + (k % 2 == 0 ? 1e-4 : -1e-4);
      r.motor_current_A = (load_kN * mp.Nm_per_kN + friction_Nm) / (mp.torque_per_A_Nm * fraction);
      m.update(r, ok, nullptr, r.force_kN, t);
    }
    return m;
  };
  ASSERT_LT(3.0, p.torque_check_moving_min_load_kN);
  ASSERT_GT(3.0, p.torque_check_moving_low_load_kN);
  EXPECT_TRUE(run(p, 1.0, 0.8, 3.0, 0.0).ok(Part::Actuator));
  auto weak = run(p, 0.3, 0.8, 3.0, 0.0);
  EXPECT_EQ(weak.diagnosis(Part::Actuator).finding, Finding::ActuatorTorqueLoss);
  EXPECT_TRUE(weak.ok(Part::LoadCell));
  // With 15 % of its torque left the drive is lost there, as above the moving check's load (at
  // 3 rev/s, faster than the unexplained-torque rule looks; 2.2 -> 3.8 kN in the run).
  ASSERT_LT(p.unexplained_max_speed_rev_per_s, 3.0);
  EXPECT_EQ(run(p, 0.15, 3.0, 2.2, 0.0).diagnosis(Part::Actuator).finding, Finding::ActuatorLost);
  MonitorParams off = p;
  off.torque_check_moving_low_load_kN = 0.0;
  EXPECT_TRUE(run(off, 0.3, 0.8, 3.0, 0.0).ok(Part::Actuator));
  MonitorParams no_curve = noiseless();
  EXPECT_TRUE(run(no_curve, 0.3, 0.8, 3.0, 0.0).ok(Part::Actuator));
  // A healthy drive holding back a release from 4.5 kN, its load cell 1.4 kN low (within the
  // curve's band): not named (its made torque, 0.13 Nm, is below check_min_torque_Nm, so no
  // balance judges it; the larger plausible load is the guard when the drive also decelerates).
  auto low = run(p, 1.0, -1.5, 4.5, -1.4);
  EXPECT_TRUE(low.ok(Part::Actuator));
  EXPECT_TRUE(low.ok(Part::LoadCell));
  EXPECT_EQ(run(p, 0.4, -1.5, 7.0, 0.0).diagnosis(Part::Actuator).finding, Finding::ActuatorTorqueLoss);
}

// A drive that seizes in a held stop (issue 14, tune_b run 376): the healthy hold sits at about
// 0 A; seized, the loop's integrators wind the current up (about 20 A/s) against a rotor that
// does not turn, while the force stays at its command. That is a lost actuator within the seized
// window (0.5 s), not a torque loss: before the winding-up rule the torque-loss fraction named it
// a torque loss after 0.3 s and the lost fraction only after 0.6 s. The same ramp while the force
// is 2 kN below its command (a drive breaking away towards a higher command), the healthy hold,
// and a steady 2x holding current (a 50 % torque loss: a torque loss) are not.
TEST(FaultMonitor, ASeizedDriveInAHoldWindsItsCurrentUpAndIsLostNotATorqueLoss) {
  MonitorParams p = noiseless();
  p.eol_curve = bbw::plant::ClampCurveParams{};
  p.eol_friction_half_width_kN = 1.0;
  const bbw::plant::ClampCurve eol{*p.eol_curve};
  const double T = p.eol_curve->reference_temperature_C;
  const double x = position_on(eol, T, 21.5);  // the position of 21.5 kN on the end-of-line curve
  SampleCheck ok;
  struct Seen {
    Diagnosis actuator;
    bool torque_loss = false;
  };
  // From 0.3 s on, the current follows current_A(time since); before, before_A (the healthy hold's 0 A).
  auto run = [&](double command_kN, auto current_A, double until_s, double before_A = 0.0) {
    FaultMonitor m(p, Target::RR);
    Seen seen;
    for (int k = 1; 0.001 * k <= until_s + 1e-12; ++k) {
      auto r = at(k, 0.001 * k, x + 2e-5 * ((k * 7) % 3), 21.5 + 0.03 * ((k % 5) - 2));
      r.temperature_C = T;
      r.speed_rev_per_s = 0.004 * ((k % 3) - 1);
      r.force_command_kN = command_kN;
      r.motor_current_A = r.time_s < 0.3 ? before_A : current_A(r.time_s - 0.3);
      m.update(r, ok, nullptr, r.force_kN, r.time_s);
      if (m.diagnosis(Part::Actuator).present && m.diagnosis(Part::Actuator).finding == Finding::ActuatorTorqueLoss) {
        seen.torque_loss = true;
      }
    }
    seen.actuator = m.diagnosis(Part::Actuator);
    return seen;
  };
  auto ramp = [](double t) { return 20.0 * t; };
  const Seen seized = run(21.5, ramp, 1.0);
  ASSERT_TRUE(seized.actuator.present);
  EXPECT_EQ(seized.actuator.finding, Finding::ActuatorLost);
  EXPECT_LT(seized.actuator.finding_s, 0.3 + 0.5) << "named lost " << seized.actuator.finding_s - 0.3 << " s into the ramp";
  EXPECT_FALSE(seized.torque_loss);
  // 2 kN below the command, a drive breaking away: the ramp's first 0.15 s (0.81 Nm, beyond any
  // friction that holds a healthy drive back) is no lost actuator. Stopped for 0.5 s of it (2.7 Nm)
  // the drive is seized, off its command too (seized_ramp_off_command_Nm, tuning seed 1401 run
  // 124); without that rule, not lost.
  EXPECT_NE(run(19.5, ramp, 0.45).actuator.finding, Finding::ActuatorLost);
  const Seen seized_off_command = run(19.5, ramp, 0.8);
  EXPECT_EQ(seized_off_command.actuator.finding, Finding::ActuatorLost);
  EXPECT_LT(seized_off_command.actuator.finding_s, 0.3 + 0.5);
  p.seized_ramp_off_command_Nm = 0.0;
  EXPECT_NE(run(19.5, ramp, 0.8).actuator.finding, Finding::ActuatorLost);
  p.seized_ramp_off_command_Nm = MonitorParams{}.seized_ramp_off_command_Nm;
  EXPECT_FALSE(run(21.5, [](double) { return 0.0; }, 2.0).actuator.present);
  const double twice_hold_A = 2.0 * 21.5 * p.Nm_per_kN / p.torque_per_A_Nm;
  const Seen half_torque = run(21.5, [&](double) { return twice_hold_A; }, 2.0, twice_hold_A);
  EXPECT_EQ(half_torque.actuator.finding, Finding::ActuatorTorqueLoss);
}

// A load-cell step while the actuator stands still (issue 14): the force cannot change, so a
// reading that leaves the still window's level and stays is a load-cell offset, at any force and
// without a fit (a 1 kN bias at 30 kN, where the end-of-line band is 2.4 kN wide). A noise spike
// that returns, and the same step while the resolver is frozen (the actuator may be moving), are not.
TEST(FaultMonitor, ALoadCellStepAtStandstillIsAnOffsetAtAnyForce) {
  MonitorParams p = noiseless();
  SampleCheck ok;
  auto run = [&](auto lc_kN, bool frozen) {
    FaultMonitor m(p, Target::FR);
    for (int k = 1; k < 300; ++k) {
      auto r = at(k, 0.001 * k, frozen ? 4.2 : 4.2 + 2e-5 * ((k * 7) % 3), lc_kN(k));
      r.motor_current_A = r.force_kN * p.Nm_per_kN / p.torque_per_A_Nm;
      m.update(r, ok, nullptr, r.force_kN, r.time_s);
    }
    return m;
  };
  auto bias = run([](int k) { return 30.0 + 0.03 * ((k % 5) - 2) + (k >= 150 ? 1.0 : 0.0); }, false);
  EXPECT_EQ(bias.diagnosis(Part::LoadCell).finding, Finding::LoadCellOffset);
  EXPECT_NEAR(bias.diagnosis(Part::LoadCell).detected_s, 0.155, 0.002);
  EXPECT_TRUE(run([](int k) { return 30.0 + (k == 150 ? 1.5 : 0.0); }, false).ok(Part::LoadCell));
  EXPECT_TRUE(run([](int k) { return 30.0 + (k >= 150 ? 1.0 : 0.0); }, true).ok(Part::LoadCell));
}

// The corners' actuator test runs every 15 ms of a hold (issue 14, eleventh session): 3 ms back,
// 3 ms forth, the rotor 0.1-1 mrev off and back by a little less. The step rule leaves the
// pulse's samples out of its still window, so a bias that comes during a pulse, or right after
// one, is still a step; a pulse alone is not, and neither is a current square that moves the
// rotor further than a test does.
// A load-cell bias during an apply, before the first fit: the still step rule waits for the rotor
// to stop and the end-of-line band for its 1-3 kN; the moving step rule names it within a few
// samples (tune_bias run 153). Healthy applies, reversals and releases on a caliper with stiff
// keys, and a noise burst while moving, are no offset; nor is a resolver jump while moving.
TEST(FaultMonitor, ALoadCellStepWhileTheActuatorMovesIsAnOffset) {
  struct Out {
    Diagnosis load_cell, resolver;
  };
  // Apply at 2 rev/s from 0.5 to 4 rev, back to 2.5 rev, forward again to 4.5 rev; the fault
  // `kind` at 1.2 s (moving forward at about 2.9 rev): 1 bias, 2 noise burst, 3 resolver jump.
  auto run = [](bool moving, int kind, double magnitude, bool stiff) {
    MonitorParams p = eol_params(1.5, stiff);
    p.step_moving = moving;
    EolCaliper caliper{p};
    auto& [eol, keys, T] = caliper;
    FaultMonitor m(p, Target::FL);
    SampleGuard g{MonitorParams{}.guard};
    std::mt19937_64 rng(7);
    std::normal_distribution<double> noise(0.0, 1.0);
    double x = 0.5;
    keys.reset(x);
    for (int n = 1; n < 5000; ++n) {
      const double t = 0.001 * n;
      const double speed = t < 1.75 ? 2.0 : t < 2.5 ? -2.0 : t < 3.5 ? 2.0 : 0.0;
      x += 0.001 * speed;
      const double friction_kN = keys.step(x);
      double lc = eol.force_kN(x, T, 0.0) + friction_kN + 0.03 * noise(rng);
      double x_read = x;
      if (t >= 1.2) {
        if (kind == 1) lc += magnitude;
        if (kind == 2 && t < 1.7) lc += magnitude * noise(rng);
        if (kind == 3) x_read += magnitude;
      }
      const auto r = live_reading(n, t, x_read, speed + 0.004 * ((n % 3) - 1), lc, p);
      const auto e = uncalibrated(lc);
      m.update(r, g.check(r), &e, e.force_kN, t);
    }
    return Out{m.diagnosis(Part::LoadCell), m.diagnosis(Part::Resolver)};
  };
  for (bool stiff : {false, true}) {
    SCOPED_TRACE(stiff ? "stiff keys" : "soft keys");
    const auto healthy = run(true, 0, 0.0, stiff);
    EXPECT_FALSE(healthy.load_cell.present) << to_string(healthy.load_cell.finding) << " at " << healthy.load_cell.detected_s;
    for (double bias_kN : {-1.0, 1.0}) {
      const auto found = run(true, 1, bias_kN, stiff);
      EXPECT_EQ(found.load_cell.finding, Finding::LoadCellOffset) << bias_kN;
      EXPECT_GE(found.load_cell.detected_s, 1.2);
      EXPECT_LT(found.load_cell.detected_s, 1.21) << bias_kN;
      const auto without = run(false, 1, bias_kN, stiff);
      EXPECT_TRUE(!without.load_cell.present || without.load_cell.detected_s > 1.3) << without.load_cell.detected_s;
    }
    const auto burst = run(true, 2, 0.4, stiff);
    EXPECT_NE(burst.load_cell.finding, Finding::LoadCellOffset) << "at " << burst.load_cell.detected_s;
    const auto jump = run(true, 3, 0.05, stiff);
    EXPECT_NE(jump.load_cell.finding, Finding::LoadCellOffset) << "at " << jump.load_cell.detected_s;
    EXPECT_EQ(jump.resolver.finding, Finding::ResolverOffset);
  }
}

TEST(FaultMonitor, ALoadCellStepDuringOrAfterAnActuatorTestIsStillAnOffset) {
  MonitorParams p = noiseless();
  p.test_pulse_current_A = 1.5;
  p.test_pulse_s = 0.003;
  SampleCheck ok;
  const double hold_A = 30.0 * p.Nm_per_kN / p.torque_per_A_Nm;
  const double a_A = hold_A + 1.5;
  // A pulse over samples 140-145; the bias (if any) from sample `bias_from`; `net_rev` where the
  // rotor stands after the pulse.
  auto run = [&](int bias_from, double net_rev) {
    FaultMonitor m(p, Target::FR);
    for (int k = 1; k < 300; ++k) {
      const double t = 0.001 * k;
      double x = 4.2 + 2e-5 * ((k * 7) % 3), speed = 0.004 * ((k % 3) - 1), current = hold_A;
      if (k >= 140 && k < 146) {
        const int i = k - 140;
        current = i < 3 ? hold_A - a_A : hold_A + a_A;
        x += net_rev * (i + 1) / 6.0;
        speed = 0.1 * (i < 3 ? -1.0 : 1.0);
      } else if (k >= 146) {
        x += net_rev;
      }
      const double lc = 30.0 + 0.03 * ((k % 5) - 2) + (bias_from > 0 && k >= bias_from ? 1.0 : 0.0);
      auto r = at(k, t, x, lc);
      r.speed_rev_per_s = speed;
      r.motor_current_A = current;
      m.update(r, ok, nullptr, r.force_kN, r.time_s);
    }
    return m.diagnosis(Part::LoadCell);
  };
  for (int from : {143, 145, 146, 150}) {
    const Diagnosis d = run(from, -6e-4);
    EXPECT_EQ(d.finding, Finding::LoadCellOffset) << "bias from sample " << from;
    EXPECT_LT(d.detected_s, 0.001 * from + 0.015) << "bias from sample " << from;
  }
  EXPECT_FALSE(run(0, -6e-4).present);  // the pulse alone
  EXPECT_FALSE(run(143, -5e-3).present);  // a square that moved the rotor 5 mrev: not a still window
}

// A drive in a hold that slips back 0.9 mrev during an actuator test, on a caliper with stiff
// keys (thresholds 2-5 mrev, 2.5 kN half-width: every element sticks at the reversal, about 700
// kN/rev together): the load cell follows the keys' friction down by about 0.6 kN with no fault.
// The still rule allows the keys' whole stiffness x the window's travel
// (step.friction_allowance) and names nothing; without it, that is a load-cell offset (stress
// seed 1406 run 311: 0.52 kN after 1 mrev in a 12 kN hold). A -1 kN bias right after the same
// creep is still named within 15 ms.
TEST(FaultMonitor, TheStillRuleAllowsTheKeysFrictionForTheWindowsTravel) {
  auto run = [](bool allowance, double bias_kN) {
    MonitorParams p = eol_params(2.5, true);
    p.step_friction_allowance = allowance;
    p.test_pulse_current_A = 1.5;
    p.test_pulse_s = 0.003;
    EolCaliper caliper{p};
    auto& [eol, keys, T] = caliper;
    FaultMonitor m(p, Target::FR);
    SampleGuard g{MonitorParams{}.guard};
    double x = 0.0;
    for (int n = 1; n < 1400; ++n) {
      const double t = 0.001 * n;
      double speed = n <= 1000 ? 4.2 : 0.004 * ((n % 3) - 1);
      if (n <= 1000) x = 0.0042 * n;
      const double hold_A = eol.force_kN(x, T, 0.0) * p.Nm_per_kN / p.torque_per_A_Nm;
      double current = hold_A;
      if (n >= 1140 && n < 1146) {  // the test: 3 ms back, 3 ms forth; 0.9 mrev back net, 0.6 of it at once
        const int i = n - 1140;
        current = i < 3 ? -1.5 : 2.0 * hold_A + 1.5;
        x -= i == 2 ? 0.6e-3 : i > 2 ? 0.1e-3 : 0.0;
        speed = i >= 2 ? -0.15 : 0.0;
      }
      const double lc = eol.force_kN(x, T, 0.0) + keys.step(x) + 0.03 * ((n % 5) - 2) + (n >= 1150 ? bias_kN : 0.0);
      auto r = live_reading(n, t, x, speed, lc, p);
      r.motor_current_A = current;
      m.update(r, g.check(r), nullptr, r.force_kN, t);
    }
    return m.diagnosis(Part::LoadCell);
  };
  const Diagnosis healthy = run(true, 0.0);
  EXPECT_FALSE(healthy.present) << to_string(healthy.finding) << " at " << healthy.detected_s;
  const Diagnosis without = run(false, 0.0);
  EXPECT_EQ(without.finding, Finding::LoadCellOffset);
  const Diagnosis bias = run(true, -1.0);
  EXPECT_EQ(bias.finding, Finding::LoadCellOffset);
  EXPECT_LT(bias.detected_s, 1.165);
}

// A drive stopped within a sample (a seizure at 20 rev/s) stands within the still span from that
// sample on, while that sample's load cell still carries the speed's viscous term (0.2 kN/(rev/s):
// 4 kN). The still rule leaves out windows with a sample measured at speed
// (step.still_max_speed_rev_per_s); without that it took the 4 kN fall for a load-cell step
// (issue 14, twenty-fourth session, effects campaign run 132). A -1 kN bias 0.2 s into the stop is
// still named at once.
TEST(FaultMonitor, TheStillRuleLeavesOutASampleTakenAtSpeed) {
  auto run = [](double max_speed_rev_per_s, double bias_kN) {
    MonitorParams p = eol_params(1.5, false);
    p.step_still_max_speed_rev_per_s = max_speed_rev_per_s;
    EolCaliper caliper{p};
    auto& [eol, keys, T] = caliper;
    FaultMonitor m(p, Target::RR);
    SampleGuard g{MonitorParams{}.guard};
    double x = 0.0;
    for (int n = 1; n < 600; ++n) {
      const double t = 0.001 * n;
      const bool moving = n <= 250;  // sample 250 reads the stop's position with the speed before it
      if (n < 250) x = 0.02 * n;
      const double speed = moving ? 20.0 : 0.004 * ((n % 3) - 1);
      const double lc = eol.force_kN(x, T, 0.0) + keys.step(x) + (moving ? 0.2 * 20.0 : 0.0) + 0.03 * ((n % 5) - 2) +
                        (n >= 450 ? bias_kN : 0.0);
      const auto r = live_reading(n, t, x, speed, lc, p);
      m.update(r, g.check(r), nullptr, r.force_kN, t);
    }
    return m.diagnosis(Part::LoadCell);
  };
  const Diagnosis healthy = run(1.0, 0.0);
  EXPECT_FALSE(healthy.present) << to_string(healthy.finding) << " at " << healthy.detected_s;
  const Diagnosis without = run(0.0, 0.0);
  EXPECT_EQ(without.finding, Finding::LoadCellOffset);
  EXPECT_LT(without.detected_s, 0.3);
  const Diagnosis bias = run(1.0, -1.0);
  EXPECT_EQ(bias.finding, Finding::LoadCellOffset);
  EXPECT_GE(bias.onset_s, 0.45 - 1e-9);
  EXPECT_LT(bias.detected_s, 0.46);
}

// Before any fit (issue 14): once the position has swept twice the largest key-friction
// threshold, the end-of-line friction model's state is known, its friction is subtracted and the
// band narrows from the whole half-width to its model share; and while the actuator holds, the
// residual keeps the level it settled at. A 0.4 kN/s load-cell drift in a held 20 kN stop (where
// the band is 0.5 + 0.6 + 0.25 x 1.5 kN wide) is found by the hold rule within 2.5 s, the
// healthy hold raises nothing.
TEST(FaultMonitor, BeforeAFitTheEndOfLineFrictionModelAndTheHoldRuleFindADrift) {
  auto run = [](double drift_kN_per_s) {
    const MonitorParams p = eol_params(1.5, false);
    EolCaliper caliper{p};  // the caliper's own keys, from an unknown state
    auto& [eol, keys, T] = caliper;
    FaultMonitor m(p, Target::FL);
    SampleGuard g{MonitorParams{}.guard};
    double x = 0.0, x_hold = 0.0;
    for (int n = 1; n < 8000; ++n) {
      const double t = 0.001 * n;
      if (t < 1.0) x = 4.6 * t;  // apply to about 20 kN
      if (n == 1000) x_hold = x;
      const double speed = t < 1.0 ? 4.6 : 0.0;
      const double drift_kN = t > 2.0 ? drift_kN_per_s * (t - 2.0) : 0.0;
      const double lc = eol.force_kN(x, T, 0.0) + keys.step(x) + drift_kN + 0.03 * ((n % 5) - 2);
      const auto r = live_reading(n, t, x, speed + 0.004 * ((n % 3) - 1), lc, p);
      const auto e = uncalibrated(lc);
      m.update(r, g.check(r), &e, lc, t);
    }
    EXPECT_NEAR(x_hold, 4.6, 0.01);
    return m.diagnosis(Part::LoadCell);
  };
  EXPECT_FALSE(run(0.0).present);
  const auto d = run(0.4);
  EXPECT_EQ(d.finding, Finding::LoadCellOffset);
  EXPECT_LT(d.detected_s, 4.5);
}

// After a resolver offset is named the resolver still measures the motion: less the offset its
// confirmed jump measured, the position the residual rules need (resolver_jump.compensate). The
// monitor gets no calibrator estimate once a sensor is diagnosed (as from CornerSupervisor): the
// end-of-line curve and band judge the load cell. An intermittent offset (+0.08 rev from 2 s,
// gone at 4 s) on a caliper that modulates +/- 0.3 rev: nothing but the resolver is named; a
// 1 kN/s load-cell drift from 2.5 s (while the offset lasts) or from 4.5 s (after it) is named
// within its window (1 kN / rate + 0.5 s); with the compensation off, neither is (the step rules
// need no position, so a drift: nothing but the residual rules sees one).
TEST(FaultMonitor, AfterAResolverOffsetTheResidualRulesGoOnAgainstThePositionLessTheOffset) {
  auto run = [](bool compensate, double drift_at_s) {
    MonitorParams p = eol_params(1.5, false);
    p.jump_compensate = compensate;
    EolCaliper caliper{p};
    auto& [eol, keys, T] = caliper;
    FaultMonitor m(p, Target::FL);
    SampleGuard g{MonitorParams{}.guard};
    double x = 0.0;
    for (int n = 1; n < 7000; ++n) {
      const double t = 0.001 * n;
      // Apply to 3.5 rev in 1 s, then modulate +/- 0.3 rev at 0.5 Hz.
      const double speed = t < 1.0 ? 3.5 : 0.3 * M_PI * std::cos(M_PI * (t - 1.0));
      x += 0.001 * speed;
      const double drift_kN = drift_at_s > 0.0 && t >= drift_at_s ? 1.0 * (t - drift_at_s) : 0.0;
      const double lc = eol.force_kN(x, T, 0.0) + keys.step(x) + drift_kN + 0.03 * ((n % 5) - 2);
      const double offset_rev = t >= 2.0 && t < 4.0 ? 0.08 : 0.0;
      const auto r = live_reading(n, t, x + offset_rev, speed + 0.004 * ((n % 3) - 1), lc, p);
      const auto e = uncalibrated(lc);
      const bool sensors_ok = m.ok(Part::LoadCell) && m.ok(Part::Resolver);
      m.update(r, g.check(r), sensors_ok ? &e : nullptr, lc, t);
    }
    return std::pair{m.diagnosis(Part::Resolver), m.diagnosis(Part::LoadCell)};
  };
  const auto [resolver, healthy] = run(true, 0.0);
  EXPECT_EQ(resolver.finding, Finding::ResolverOffset) << to_string(resolver.finding);
  EXPECT_NEAR(resolver.detected_s, 2.01, 0.005);
  EXPECT_FALSE(healthy.present) << to_string(healthy.finding) << " at " << healthy.detected_s;
  for (double drift_at_s : {2.5, 4.5}) {
    const double window_end_s = drift_at_s + 1.0 / 1.0 + 0.5;
    const auto d = run(true, drift_at_s).second;
    EXPECT_EQ(d.finding, Finding::LoadCellOffset) << to_string(d.finding);
    EXPECT_GT(d.detected_s, drift_at_s);
    EXPECT_LT(d.detected_s, window_end_s);
    const auto without = run(false, drift_at_s).second;
    EXPECT_TRUE(!without.present || without.detected_s > window_end_s) << without.detected_s;
  }
}

// The sum of the confirmed jumps is the resolver's offset only while every step was seen. An
// offset that began while the link was silent and ended in sight (CI subset run 32) left a sum of
// the wrong sign, and the compensated residual named a healthy load cell: after a gap the offset
// is no longer tracked (and the monitor no longer compensates).
TEST(JumpDetector, AfterAGapTheSumOfTheJumpsIsNoLongerTheOffset) {
  auto run = [](bool gap) {
    JumpDetector jump;
    DiagnosisArbiter a;
    const MonitorParams p;
    const SampleCheck check{};
    CornerReading prev;
    bool have_prev = false;
    for (int n = 1; n < 400; ++n) {
      if (gap && n >= 100 && n < 150) continue;  // the link is silent: the offset begins unseen
      CornerReading r = at(static_cast<std::uint64_t>(n), 0.001 * n, n >= 120 && n < 300 ? -0.2 : 0.0, 10.0);
      const SampleContext c{r, check, have_prev, prev, true, have_prev ? r.time_s - prev.time_s : 0.0};
      jump.update(c, p, a);
      prev = r;
      have_prev = true;
    }
    return std::pair{jump, a.diagnosis(Part::Resolver)};
  };
  const auto [seen, seen_d] = run(false);
  EXPECT_EQ(seen_d.finding, Finding::ResolverOffset);
  EXPECT_TRUE(seen.offset_tracked());
  EXPECT_EQ(seen.confirmed(), 2);                 // on at 0.12 s, off at 0.3 s
  EXPECT_NEAR(seen.offset_rev(), 0.0, 1e-9);
  const auto [hidden, hidden_d] = run(true);
  EXPECT_EQ(hidden_d.finding, Finding::ResolverOffset);  // its end
  EXPECT_EQ(hidden.confirmed(), 1);
  EXPECT_NEAR(hidden.offset_rev(), 0.2, 1e-9);           // the wrong sign: not the offset (0 now)
  EXPECT_FALSE(hidden.offset_tracked());
}

// The hold rule's reference belongs to one way of computing the residual (extreme population,
// 2026-11-26, run 75: a healthy stiff caliper named load_cell_offset). A slow apply (0.3 rev/s,
// a hold to the rule) that begins a few samples before the end-of-line friction model's state
// becomes known: the residual drops by the whole friction (about 1.5 kN) at that moment. Before
// the fix the reference then completed as the mean of samples from both sides of the drop and
// the hold rule took the drop for a 1.1-1.5 kN change; now the change of definition restarts the
// settling too, and nothing is raised, whichever sample the drop falls on.
TEST(FaultMonitor, TheHoldRuleRestartsWhenTheFrictionModelComesInWhileItSettles) {
  MonitorParams p = eol_params(1.5, false);
  p.hold_span_rev = 10.0;  // no restart by distance: only the definition's change matters here
  const double sweep_rev = 2.0 * bbw::plant::KeyFriction{*p.eol_key_friction}.thresholds_rev().back();
  const double x0 = 2.0, slow = 0.3, fast = 1.0;
  int findings = 0;
  for (int before : {2, 6, 10, 14, 18}) {  // settling samples before the friction model comes in
    EolCaliper caliper{p};
    auto& [eol, keys, T] = caliper;
    FaultMonitor m(p, Target::FL);
    SampleGuard g{MonitorParams{}.guard};
    const double x_slow = x0 + sweep_rev - (before + 0.5) * slow * 0.001;  // where the slow part begins
    double x = x0;
    for (int n = 1; n < 4000; ++n) {
      const double t = 0.001 * n;
      const double speed = x < x_slow ? fast : slow;
      x += speed * 0.001;
      const double lc = eol.force_kN(x, T, 0.0) + keys.step(x) + 0.03 * ((n % 5) - 2);
      const auto r = live_reading(n, t, x, speed + 0.004 * ((n % 3) - 1), lc, p);
      const auto e = uncalibrated(lc);
      m.update(r, g.check(r), &e, lc, t);
    }
    EXPECT_FALSE(m.diagnosis(Part::LoadCell).present) << before << " settling samples before the friction model came in";
    findings += m.diagnosis(Part::LoadCell).present ? 1 : 0;
  }
  EXPECT_EQ(findings, 0);
}

// The noise rule reads the raw load cell against the curve at the position (issue 14): an
// estimate that is filtered (as the CCU's is) does not hide a 0.35 kN RMS burst in a held stop.
TEST(FaultMonitor, ANoiseBurstIsFoundInTheRawLoadCellNotTheFilteredEstimate) {
  MonitorParams p;
  SampleCheck ok;
  FaultMonitor m(p, Target::FL);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> burst(0.0, 0.35);
  for (int k = 1; k < 400; ++k) {
    // A live load cell and resolver (their noise: a channel repeating exactly is frozen).
    const double lc = 30.0 + 0.03 * ((k % 5) - 2) + (k > 200 ? burst(rng) : 0.0);
    auto r = at(k, 0.001 * k, 5.8 + 2e-5 * ((k * 7) % 3), lc);
    r.speed_rev_per_s = 0.004 * ((k % 3) - 1);
    const auto e = estimate(30.0, 30.0);  // filtered: the burst does not reach it
    m.update(r, ok, &e, e.force_kN, r.time_s);
  }
  EXPECT_EQ(m.diagnosis(Part::LoadCell).finding, Finding::LoadCellNoisy);
}

// Released (below the trusted range, where the residual is not judged) a noise burst is found in
// the load cell's own second differences (noise.released, twenty-second session: tuning seed 1403
// run 506, a 0.55 kN RMS burst from 0.56 s with the pads off the disc, named only at 1.28 s). A
// healthy load cell noisier than the population's (0.15 kN RMS) is not noisy, also in the first
// 0.1 s before its level is learnt. Without the rule the burst is not named noisy (here the low
// bounds name it an offset 0.8 s later).
TEST(FaultMonitor, ANoiseBurstWhileReleasedIsFoundInTheLoadCellsSecondDifferences) {
  MonitorParams p;
  p.eol_curve = bbw::plant::ClampCurveParams{};
  p.eol_friction_half_width_kN = 1.0;
  SampleCheck ok;
  auto run = [&](double burst_from_s) {
    FaultMonitor m(p, Target::RL);
    std::mt19937_64 rng(5);
    std::normal_distribution<double> cell(0.0, 0.15), burst(0.0, 0.55);
    for (int k = 1; k <= 3000; ++k) {
      const double t = 0.001 * k;
      const double lc = 0.5 + cell(rng) + (t >= burst_from_s ? burst(rng) : 0.0);
      auto r = at(k, t, 0.3 + 2e-5 * ((k * 7) % 3), lc);
      r.speed_rev_per_s = 0.004 * ((k % 3) - 1);
      const auto e = uncalibrated(lc);
      m.update(r, ok, &e, lc, t);
      if (m.diagnosis(Part::LoadCell).present) return m.diagnosis(Part::LoadCell);
    }
    return m.diagnosis(Part::LoadCell);
  };
  ASSERT_LT(0.3 + 4e-5, p.curve_min_rev);  // released: below the trusted range throughout
  const Diagnosis healthy = run(1e9);
  EXPECT_FALSE(healthy.present) << "named " << to_string(healthy.finding) << " at " << healthy.detected_s << " s";
  const Diagnosis burst = run(0.5);
  ASSERT_TRUE(burst.present);
  EXPECT_EQ(burst.finding, Finding::LoadCellNoisy);
  EXPECT_GE(burst.detected_s, 0.5);
  EXPECT_LT(burst.detected_s, 0.55);
  p.noise_released = false;
  const Diagnosis without = run(0.5);
  EXPECT_NE(without.finding, Finding::LoadCellNoisy) << "named at " << without.detected_s << " s";
}

// A healthy load cell noisier than the population's (0.1 kN RMS against at most 0.05 kN) is not
// noisy once the corner has learnt its own level (noise.learned_factor, learn_time_constant_s:
// stress population 2026-11-26, a 0.079 kN load cell named noisy at 6.8 s); a 0.35 kN RMS burst
// on top of it still is.
TEST(FaultMonitor, TheNoiseRuleLearnsTheCornersOwnLevel) {
  SampleCheck ok;
  auto run = [&](const MonitorParams& p, double burst_from_s) {
    FaultMonitor m(p, Target::FL);
    std::mt19937_64 rng(11);
    std::normal_distribution<double> cell(0.0, 0.1), burst(0.0, 0.35);
    for (int k = 1; k <= 30000; ++k) {
      const double t = 0.001 * k;
      const double lc = 30.0 + cell(rng) + (t >= burst_from_s ? burst(rng) : 0.0);
      auto r = at(k, t, 5.8 + 2e-5 * ((k * 7) % 3), lc);
      r.speed_rev_per_s = 0.004 * ((k % 3) - 1);
      const auto e = estimate(30.0, 30.0);
      m.update(r, ok, &e, e.force_kN, r.time_s);
      if (m.diagnosis(Part::LoadCell).present) return m.diagnosis(Part::LoadCell);
    }
    return m.diagnosis(Part::LoadCell);
  };
  MonitorParams fixed;
  fixed.noise_learned_factor = 0.0;  // the fixed step alone: this load cell looks noisy
  const Diagnosis before = run(fixed, 1e9);
  ASSERT_TRUE(before.present);
  EXPECT_EQ(before.finding, Finding::LoadCellNoisy);
  const MonitorParams learnt;
  const Diagnosis healthy = run(learnt, 1e9);
  EXPECT_FALSE(healthy.present) << "named " << to_string(healthy.finding) << " at " << healthy.detected_s << " s";
  const Diagnosis burst = run(learnt, 10.0);
  ASSERT_TRUE(burst.present);
  EXPECT_EQ(burst.finding, Finding::LoadCellNoisy);
  EXPECT_GE(burst.detected_s, 10.0);
  EXPECT_LT(burst.detected_s, 10.1);
}

// With an end-of-line curve the noise rule reads the load cell against it (issue 14): a fast
// release beyond the fitted range, where the calibrator's curve has the wrong slope, is not noise
// (tuning run 367: load_cell_noisy on two healthy corners in a 15 rev/s release from 36 kN).
TEST(FaultMonitor, AFastReleaseWhereTheFittedCurveHasTheWrongSlopeIsNotNoise) {
  MonitorParams p;
  p.eol_curve = bbw::plant::ClampCurveParams{};
  const bbw::plant::ClampCurve eol{*p.eol_curve};
  const double T = p.eol_curve->reference_temperature_C;
  SampleCheck ok;
  FaultMonitor m(p, Target::FR);
  for (int k = 1; k < 150; ++k) {
    const double x = 7.2 - 0.016 * k;  // 16 rev/s down from 7.2 rev
    const double lc = eol.force_kN(x, T, 0.0) + 0.03 * ((k % 5) - 2);
    auto r = at(k, 0.001 * k, x, lc);
    r.speed_rev_per_s = -16.0;
    r.temperature_C = T;
    r.motor_current_A = -5.0;
    auto e = estimate(lc, 0.0);  // a fitted curve far off its range (none at all here)
    e.calibrated = false;
    m.update(r, ok, &e, lc, r.time_s);
  }
  EXPECT_TRUE(m.ok(Part::LoadCell)) << to_string(m.diagnosis(Part::LoadCell).finding);
}

// Calibrated, the residual is judged against two models of the key friction (issue 14): the
// calibrator's and the end-of-line one. At a reversal a caliper's keys can flip within 0.02 rev,
// which the calibrator's elements (fitted on their own thresholds) follow late; the end-of-line
// model follows it. A fault-free release is no finding (tuning seed 1403 run 601: a 2.8 kN
// disagreement at a release from 24 kN, `load_cell_offset` on a healthy corner, with the
// calibrator's friction alone); a 2.5 kN load-cell bias in the hold (beyond the first fit's
// starting band, the key-friction width + 0.5 kN) moves the load cell against both.
TEST(FaultMonitor, CalibratedTheResidualIsJudgedAgainstBothFrictionModels) {
  auto run = [](bool two_models, double bias_kN) {
    MonitorParams p = eol_params(1.5, true);
    p.calibrated_two_friction_models = two_models;
    EolCaliper caliper{p};  // the caliper's own keys, from an unknown state
    auto& [eol, keys, T] = caliper;
    FaultMonitor m(p, Target::FL);
    SampleGuard g{MonitorParams{}.guard};
    double x = 0.0;
    for (int n = 1; n < 3000; ++n) {
      const double t = 0.001 * n;
      // Apply to about 20 kN, hold, release at 1 rev/s from 2.0 s.
      const double speed = t < 1.0 ? 4.6 : t < 2.0 ? 0.0 : -1.0;
      x += 0.001 * speed;
      const double friction_kN = keys.step(x);
      const double lc = eol.force_kN(x, T, 0.0) + friction_kN + (t > 1.5 ? bias_kN : 0.0) + 0.03 * ((n % 5) - 2);
      const auto r = live_reading(n, t, x, speed + 0.004 * ((n % 3) - 1), lc, p);
      // The calibrator: fitted from 0.5 s, its friction right in the apply and the hold, but
      // following the release's flip only over 0.1 rev.
      const double lag_kN = t < 2.0 ? 1.5 : std::max(-1.5, 1.5 - 30.0 * (t - 2.0));
      const auto e = fitted(t > 0.5, lc, t < 2.0 ? friction_kN : lag_kN, eol.force_kN(x, T, 0.0));
      m.update(r, g.check(r), &e, e.force_kN, t);
    }
    return m.diagnosis(Part::LoadCell);
  };
  // The calibrator's friction alone: the release is taken for a load-cell fault.
  EXPECT_EQ(run(false, 0.0).finding, Finding::LoadCellOffset);
  EXPECT_FALSE(run(true, 0.0).present) << to_string(run(true, 0.0).finding);
  const auto d = run(true, 2.5);
  EXPECT_EQ(d.finding, Finding::LoadCellOffset);
  EXPECT_LT(d.detected_s, 1.6);
}

// The change rule's speed allowance follows the speed's change since the reference's level
// (issue 14): stopping an 8 rev/s release on a caliper with viscous friction (0.2 kN per rev/s)
// moves the residual by 1.6 kN within 30 ms, while the reference, a 0.1 s low-pass, still
// holds the release's level (tuning seed 1403 run 57: `load_cell_offset` on a healthy corner).
// A 1 kN load-cell bias in the hold after it is still found.
TEST(FaultMonitor, StoppingAFastReleaseOnAViscousCaliperIsNotAChange) {
  auto run = [](double bias_kN) {
    MonitorParams p;
    SampleCheck ok;
    FaultMonitor m(p, Target::RR);
    double x = 5.5;
    for (int k = 1; k < 1500; ++k) {
      const double t = 0.001 * k;
      const double v = t < 0.1 ? 0.0 : t < 0.4 ? -8.0 : t < 0.43 ? -8.0 * (0.43 - t) / 0.03 : 0.0;
      x += 0.001 * v;
      const double curve_kN = 6.0 * x;
      const double lc = curve_kN + 0.2 * v + (t > 1.0 ? bias_kN : 0.0) + 0.02 * ((k % 5) - 2);
      auto r = at(k, t, x + 2e-5 * ((k * 7) % 3), lc);  // a live resolver's noise
      r.speed_rev_per_s = v + 0.004 * ((k % 3) - 1);
      const auto e = estimate(lc, curve_kN);
      m.update(r, ok, &e, e.force_kN, t);
    }
    return m.diagnosis(Part::LoadCell);
  };
  const auto healthy = run(0.0);
  EXPECT_FALSE(healthy.present) << to_string(healthy.finding) << " at " << healthy.detected_s;
  const auto biased = run(1.0);
  EXPECT_EQ(biased.finding, Finding::LoadCellOffset) << to_string(biased.finding);
  EXPECT_LT(biased.detected_s, 1.05);
}

// The noise rule allows a step the model itself made in that sample (issue 14): a load cell
// 5 ms late (sensor delay) at an ABS reversal, where the key friction flips by 3 kN within
// 5 ms, steps the residual twice (once with the model, once with the load cell): 8 of 32 large
// steps, `load_cell_noisy` on healthy corners (tune_b runs 591 and 601). A 0.35 kN RMS noise
// burst in the same cycling is still found.
TEST(FaultMonitor, ALoadCellThatFollowsTheModelLateIsNotNoise) {
  auto run = [](double noise_rms_kN) {
    const MonitorParams p = eol_params(1.5, true);
    EolCaliper caliper{p};  // the caliper's own keys, from an unknown state
    auto& [eol, keys, T] = caliper;
    FaultMonitor m(p, Target::RR);
    SampleGuard g{MonitorParams{}.guard};
    std::mt19937_64 rng(11);
    std::normal_distribution<double> noise(0.0, 1.0);
    std::array<double, 5> late{};  // the load cell 5 samples late
    double x = 0.0;
    for (int n = 1; n < 3000; ++n) {
      const double t = 0.001 * n;
      // Apply to about 20 kN, then ABS-like cycling: +/- 0.3 rev at 6 Hz (up to 11 rev/s).
      const double speed = t < 1.0 ? 4.6 : 0.3 * 2.0 * M_PI * 6.0 * std::cos(2.0 * M_PI * 6.0 * (t - 1.0));
      x += 0.001 * speed;
      const double model_kN = eol.force_kN(x, T, 0.0) + keys.step(x);
      const double lc = late[n % 5] + 0.03 * noise(rng) + (t > 2.0 ? noise_rms_kN * noise(rng) : 0.0);
      late[n % 5] = model_kN;
      const auto r = live_reading(n, t, x, speed, lc, p);
      const auto e = uncalibrated(lc);
      m.update(r, g.check(r), &e, lc, t);
      if (m.diagnosis(Part::LoadCell).present) break;
    }
    return m.diagnosis(Part::LoadCell);
  };
  const auto healthy = run(0.0);
  EXPECT_FALSE(healthy.present) << to_string(healthy.finding) << " at " << healthy.detected_s;
  const auto noisy = run(0.35);
  EXPECT_EQ(noisy.finding, Finding::LoadCellNoisy) << to_string(noisy.finding);
  EXPECT_LT(noisy.detected_s, 2.2);
}

namespace {
// The drift tests below show what one rule adds by switching it off; they run with an end-of-line
// test accurate to 3 % (as shipped until the sixteenth session). With the shipped 1 % the band,
// or the learnt thresholds capped at it, alone name these drifts within their windows, and
// switching one rule off would show nothing.
constexpr double kEolRelativeUntilSession16 = 0.03;
}  // namespace

// The hold rule on calibrated corners too (issue 14): the corner's learnt residual statistics
// start at the end-of-line band after the first fit and follow a slow drift (a 1.28 kN/s drift in
// a held 22 kN stop, tuning seed 1403 run 744: the threshold rose from 1.15 to 1.6 kN while the
// residual crept to 1.2 kN, found 8.5 s late as `actuator_torque_loss`). The hold's settled
// level does not follow: a 0.6 kN/s drift from 4 s is found within its scoring window
// (1.0 kN / 0.6 kN/s + 0.5 s), a healthy hold raises nothing.
// A calibrated corner whose residual carries a model error (0.3 kN with the position) learns
// its threshold from it; a 1 kN/s load-cell drift while the brake modulates (never a hold) grows
// under that threshold. Learnt in full, the drift's own square widened the threshold as fast as
// the drift grew (tune_bias run 38); bounded at stats_clip sigmas, it is named in its window.
TEST(FaultMonitor, ASlowDriftCannotWidenTheLearntThresholdAsFastAsItGrows) {
  auto run = [](double clip, double drift_kN_per_s) {
    MonitorParams p = eol_params(1.5, false);
    p.hold_calibrated = false;  // the residual rule alone
    p.revisit = false;          // (the revisit rule, twenty-first session, names this drift at 12.77 s)
    p.residual_stats_clip = clip;
    p.eol_relative = kEolRelativeUntilSession16;
    EolCaliper caliper{p};
    auto& [eol, keys, T] = caliper;
    FaultMonitor m(p, Target::RL);
    SampleGuard g{MonitorParams{}.guard};
    double x = 0.0;
    for (int n = 1; n < 16000; ++n) {
      const double t = 0.001 * n;
      // Apply to 3.5 rev, then modulate +/- 0.4 rev at 0.6 Hz.
      const double speed = t < 1.0 ? 3.5 : 0.4 * 2.0 * M_PI * 0.6 * std::cos(2.0 * M_PI * 0.6 * (t - 1.0));
      x += 0.001 * speed;
      const double friction_kN = keys.step(x);
      const double model_error_kN = 0.3 * std::sin(2.0 * M_PI * x / 0.37);
      const double drift_kN = t > 12.0 ? drift_kN_per_s * (t - 12.0) : 0.0;
      const double lc = eol.force_kN(x, T, 0.0) + friction_kN + model_error_kN + drift_kN + 0.03 * ((n % 5) - 2);
      const auto r = live_reading(n, t, x, speed + 0.004 * ((n % 3) - 1), lc, p);
      const auto e = fitted(t > 0.5, lc, friction_kN, eol.force_kN(x, T, 0.0));
      m.update(r, g.check(r), &e, e.force_kN, t);
    }
    return m.diagnosis(Part::LoadCell);
  };
  const double window_end_s = 12.0 + 1.0 / 1.0 + 0.5;
  const auto unbounded = run(0.0, 1.0);
  EXPECT_TRUE(!unbounded.present || unbounded.detected_s > window_end_s) << unbounded.detected_s;
  const auto healthy = run(1.5, 0.0);
  EXPECT_FALSE(healthy.present) << to_string(healthy.finding) << " at " << healthy.detected_s;
  const auto d = run(1.5, 1.0);
  EXPECT_EQ(d.finding, Finding::LoadCellOffset) << to_string(d.finding);
  EXPECT_GT(d.detected_s, 12.0);
  EXPECT_LT(d.detected_s, window_end_s);
}

namespace {

// The end-of-line caliper of `p` applied to about 20 kN (4.6 rev/s for 1 s) and held until 8 s,
// its load cell drifting at drift_kN_per_s from 4 s; view(t, load cell, friction, curve) is the
// calibrator's estimate the monitor gets. Returns the load cell's diagnosis.
template <class View>
Diagnosis drift_in_a_hold(const MonitorParams& p, double drift_kN_per_s, View view) {
  EolCaliper caliper{p};  // the caliper's own keys, from an unknown state
  auto& [eol, keys, T] = caliper;
  FaultMonitor m(p, Target::RL);
  SampleGuard g{MonitorParams{}.guard};
  double x = 0.0;
  for (int n = 1; n < 8000; ++n) {
    const double t = 0.001 * n;
    const double speed = t < 1.0 ? 4.6 : 0.0;
    x += 0.001 * speed;
    const double friction_kN = keys.step(x);
    const double drift_kN = t > 4.0 ? drift_kN_per_s * (t - 4.0) : 0.0;
    const double lc = eol.force_kN(x, T, 0.0) + friction_kN + drift_kN + 0.03 * ((n % 5) - 2);
    const auto r = live_reading(n, t, x, speed + 0.004 * ((n % 3) - 1), lc, p);
    const auto e = view(t, lc, friction_kN, eol.force_kN(x, T, 0.0));
    m.update(r, g.check(r), &e, e.force_kN, t);
  }
  return m.diagnosis(Part::LoadCell);
}

}  // namespace

// A drift that starts in a hold before the first fit: the fit, mid-hold, changes how the
// residual is computed. Restarting the hold there threw away the change the drift had made
// (tune_bias run 10: 0.5 kN in a held hard stop); rebased, the hold carries it across.
TEST(FaultMonitor, AHoldCarriesADriftsChangeAcrossTheFirstFit) {
  auto run = [](bool rebase, double drift_kN_per_s) {
    MonitorParams p = eol_params(1.5, false);
    p.hold_rebase = rebase;
    p.revisit = false;  // the hold rule alone (the revisit rule, twenty-first session, names it at 5.15 s)
    // The whole friction share, so that the drift outlives the first fit (with the allowance as
    // the friction moved, twenty-first session, it is named before the fit, at 4.96 s).
    p.hold_friction_as_moved = false;
    p.eol_relative = kEolRelativeUntilSession16;
    // The first fit comes at 5 s, in the hold; before it, the load cell as it is.
    return drift_in_a_hold(p, drift_kN_per_s, [](double t, double lc, double friction_kN, double curve_kN) {
      return t > 5.0 ? fitted(true, lc, friction_kN, curve_kN) : uncalibrated(lc);
    });
  };
  const double window_end_s = 4.0 + 1.0 / 0.6 + 0.5;
  const auto restarted = run(false, -0.6);
  EXPECT_TRUE(!restarted.present || restarted.detected_s > window_end_s) << restarted.detected_s;
  const auto healthy = run(true, 0.0);
  EXPECT_FALSE(healthy.present) << to_string(healthy.finding) << " at " << healthy.detected_s;
  const auto d = run(true, -0.6);
  EXPECT_EQ(d.finding, Finding::LoadCellOffset) << to_string(d.finding);
  EXPECT_GT(d.detected_s, 5.0);
  EXPECT_LT(d.detected_s, window_end_s);
}

TEST(FaultMonitor, CalibratedAHoldKeepsItsLevelWhileTheLearntStatisticsFollowADrift) {
  const double running = MonitorParams{}.residual_stats_prior_s;
  const double exponential = MonitorParams{}.residual_stats_s;  // the learning before the thirteenth session
  auto run = [](bool hold_calibrated, double drift_kN_per_s, double prior_s) {
    MonitorParams p = eol_params(1.5, false);
    p.eol_relative = kEolRelativeUntilSession16;  // with 1 % the capped thresholds alone: 5.93 s
    p.hold_calibrated = hold_calibrated;
    p.residual_stats_prior_s = prior_s;
    // The hold rule and the learnt statistics alone: the revisit rule (twenty-first session)
    // names this drift by itself too (5.15 s), where the hold began.
    p.revisit = false;
    // Calibrated from 0.5 s, its friction right.
    return drift_in_a_hold(p, drift_kN_per_s, [](double t, double lc, double friction_kN, double curve_kN) {
      return fitted(t > 0.5, lc, friction_kN, curve_kN);
    });
  };
  const double window_end_s = 4.0 + 1.0 / 0.6 + 0.5;
  // With the statistics learnt exponentially from the end-of-line band, only the hold rule finds it.
  const auto without = run(false, -0.6, exponential);
  EXPECT_TRUE(!without.present || without.detected_s > window_end_s) << without.detected_s;
  for (double prior_s : {exponential, running}) {
    const auto healthy = run(true, 0.0, prior_s);
    EXPECT_FALSE(healthy.present) << to_string(healthy.finding) << " at " << healthy.detected_s;
    const auto d = run(true, -0.6, prior_s);
    EXPECT_EQ(d.finding, Finding::LoadCellOffset) << to_string(d.finding);
    EXPECT_LT(d.detected_s, window_end_s);
  }
  // Learnt as a running mean at first, the corner's own 4 sigma comes within 2 s of the fit and
  // the residual rule finds it by itself too (thirteenth session).
  const auto learnt = run(false, -0.6, running);
  EXPECT_EQ(learnt.finding, Finding::LoadCellOffset) << to_string(learnt.finding);
  EXPECT_LT(learnt.detected_s, window_end_s);
  EXPECT_FALSE(run(false, 0.0, running).present);
}

// The hold rule's friction allowance (hold.friction_as_moved): in a hold after an apply the keys
// stay slipping the way they were, in the end-of-line model and on the caliper, so the model's
// share of the friction's width is not needed; only the share of what the model's friction moved
// since the hold settled. A -0.3 kN/s drift from 4 s in a held apply (the revisit rule off, to
// judge the hold rule alone): named once the change passes 0.5 kN instead of 0.5 kN + a quarter
// of the 1.5 kN half-width.
TEST(FaultMonitor, AHoldWhoseKeysKeptSlippingOneWayNeedsNoFrictionAllowance) {
  auto run = [](bool as_moved, double drift_kN_per_s) {
    MonitorParams p = eol_params(1.5, false);
    p.hold_friction_as_moved = as_moved;
    p.revisit = false;
    return drift_in_a_hold(p, drift_kN_per_s, [](double t, double lc, double friction_kN, double curve_kN) {
      return fitted(t > 0.5, lc, friction_kN, curve_kN);
    });
  };
  const auto healthy = run(true, 0.0);
  EXPECT_FALSE(healthy.present) << to_string(healthy.finding) << " at " << healthy.detected_s;
  const auto with = run(true, -0.3);
  const auto without = run(false, -0.3);
  EXPECT_EQ(with.finding, Finding::LoadCellOffset) << to_string(with.finding);
  EXPECT_EQ(without.finding, Finding::LoadCellOffset) << to_string(without.finding);
  // 0.5 kN and 0.875 kN (+ the curve's 1 %) of a 0.3 kN/s drift: 1.25 s sooner.
  EXPECT_LT(with.detected_s, 4.0 + 0.6 / 0.3);
  EXPECT_GT(without.detected_s, 4.0 + 0.85 / 0.3);
  std::printf("a -0.3 kN/s drift from 4 s in a hold: named at %.3f s (with the whole share: %.3f s)\n", with.detected_s,
              without.detected_s);
}

// The hold rule's friction allowance before the end-of-line friction model's state is known
// (hold.friction_swing): keys whose elements slip only after 1.5-3 rev (so the 4.6 rev apply
// leaves their state unknown) can move in a still hold by no more than their stiffness times the
// resolver's noise, not by a half-width. A -0.6 kN/s drift from 4 s in the hold, never calibrated:
// named once the change passes about 0.5 kN instead of 0.5 kN + the 1.5 kN half-width.
TEST(FaultMonitor, AStillHoldBeforeTheKeysAreKnownNeedsOnlyTheFrictionItsSpanCanMove) {
  auto run = [](bool swing, double drift_kN_per_s) {
    MonitorParams p = eol_params(1.5, false);
    p.eol_key_friction->threshold_distribution = bbw::plant::ThresholdDistribution::LogUniform;
    p.eol_key_friction->threshold_min_rev = 1.5;
    p.eol_key_friction->threshold_max_rev = 3.0;
    p.hold_friction_swing = swing;
    return drift_in_a_hold(p, drift_kN_per_s, [](double, double lc, double, double) { return uncalibrated(lc); });
  };
  const auto healthy = run(true, 0.0);
  EXPECT_FALSE(healthy.present) << to_string(healthy.finding) << " at " << healthy.detected_s;
  const auto with = run(true, -0.6);
  const auto without = run(false, -0.6);
  EXPECT_EQ(with.finding, Finding::LoadCellOffset) << to_string(with.finding);
  EXPECT_LT(with.detected_s, 4.0 + 0.8 / 0.6);
  EXPECT_TRUE(!without.present || without.detected_s > 4.0 + 1.9 / 0.6) << without.detected_s;
  std::printf("a -0.6 kN/s drift from 4 s in a still hold, the keys' state unknown: named at %.3f s (one half-width: %s at %.3f s)\n",
              with.detected_s, to_string(without.finding), without.detected_s);
}

// A calibrated corner modulated like an ABS (6 Hz, +-0.15 rev about 4.5 rev, up to 5.7 rev/s),
// its calibrator right about the friction: the clamp curve `stiffness` x the end-of-line one, the
// load cell `speed_kN_per_rev_per_s` x the speed off the clamp force (a sensor delay, viscous
// keys), and a load-cell drift from 4 s. Returns the load cell's diagnosis at 7 s.
namespace {
Diagnosis modulated_corner(const MonitorParams& p, double stiffness, double speed_kN_per_rev_per_s, double drift_kN_per_s) {
  EolCaliper caliper{p};
  auto& [eol, keys, T] = caliper;
  FaultMonitor m(p, Target::FR);
  SampleGuard g{MonitorParams{}.guard};
  for (int n = 1; n < 7000; ++n) {
    const double t = 0.001 * n;
    const double w = 2.0 * M_PI * 6.0;
    const double speed = t >= 1.0 ? 0.15 * w * std::cos(w * (t - 1.0)) : 4.5;
    const double x = t < 1.0 ? 4.5 * t : 4.5 + 0.15 * std::sin(w * (t - 1.0));
    const double friction_kN = keys.step(x);
    const double drift_kN = t > 4.0 ? drift_kN_per_s * (t - 4.0) : 0.0;
    const double clamp_kN = stiffness * eol.force_kN(x, T, 0.0);
    const double lc = clamp_kN + friction_kN + speed_kN_per_rev_per_s * speed + drift_kN + 0.03 * ((n % 5) - 2);
    const auto r = live_reading(n, t, x, speed + 0.004 * ((n % 3) - 1), lc, p);
    const auto e = fitted(t > 0.5, lc, friction_kN, clamp_kN);
    m.update(r, g.check(r), &e, e.force_kN, t);
  }
  return m.diagnosis(Part::LoadCell);
}

// What a drift rule on the modulated corner must show: `run(rule_on, drift_kN_per_s)` gives the
// load cell's diagnosis. Healthy, nothing; a -1 kN/s drift from 4 s named inside its window
// (4 s + 1 kN / 1 kN/s + 0.5 s) with the rule and not without it; and a +1 kN/s drift too.
void expect_drift_rule(const char* rule, const std::function<Diagnosis(bool, double)>& run) {
  const double window_end_s = 4.0 + 1.0 / 1.0 + 0.5;
  const auto healthy = run(true, 0.0);
  EXPECT_FALSE(healthy.present) << rule << ": " << to_string(healthy.finding) << " at " << healthy.detected_s;
  const auto without = run(false, -1.0);
  EXPECT_TRUE(!without.present || without.detected_s > window_end_s) << rule << ": " << without.detected_s;
  const auto with = run(true, -1.0);
  EXPECT_EQ(with.finding, Finding::LoadCellOffset) << rule << ": " << to_string(with.finding);
  EXPECT_GT(with.detected_s, 4.0) << rule;
  EXPECT_LT(with.detected_s, window_end_s) << rule;
  const auto up = run(true, 1.0);
  EXPECT_EQ(up.finding, Finding::LoadCellOffset) << rule << ": " << to_string(up.finding);
  EXPECT_LT(up.detected_s, window_end_s) << rule;
  std::printf("%s: drift -1 kN/s from 4 s named at %.3f s (without it: %s %.3f s), +1 kN/s at %.3f s\n", rule,
              with.detected_s, without.present ? "named at" : "not named;", without.detected_s, up.detected_s);
}
}  // namespace

// The revisit rule: the modulated corner above, its clamp curve 3 % stiffer than its end-of-line
// one (within the band, but 0.6 kN of it at 20 kN). A -1 kN/s load-cell drift from 4 s: at speed
// the level rule's allowance grows by 0.3 kN per rev/s and the residual starts 0.6 kN up, so the
// level rule finds the drift only after its window (4 s + 1 kN / 1 kN/s + 0.5 s); where the
// drive has been before, the residual has kept its level within 0.1 kN, and the drift shows
// there from about 0.6 kN.
TEST(FaultMonitor, TheRevisitRuleFindsADriftWhereTheDriveHasBeenBefore) {
  auto run = [](bool revisit, double drift_kN_per_s) {
    MonitorParams p = eol_params(1.5, false);
    p.revisit = revisit;
    p.modulation = false;  // the revisit rule alone (the modulation rule's test is below)
    return modulated_corner(p, 1.03, 0.0, drift_kN_per_s);
  };
  expect_drift_rule("revisit rule", run);
}

// The modulation rule: the modulated corner above, its clamp curve the end-of-line one, its load
// cell 0.1 kN per rev/s of speed off the clamp force, the revisit rule off. The level rule's
// allowance grows by 0.3 kN per rev/s beyond 3 rev/s, so a -1 kN/s drift from 4 s is over it only
// around the reversals, for less than its persistence, until 0.13 s after its window. Fitted as
// c + a v + b sign(v) over the last 0.2 s, the residual at standstill is judged against the
// threshold at standstill: named 0.2 s inside it, either way.
TEST(FaultMonitor, TheModulationRuleJudgesTheResidualAtStandstill) {
  auto run = [](bool modulation, double drift_kN_per_s) {
    MonitorParams p = eol_params(1.5, false);
    p.revisit = false;
    p.modulation = modulation;
    return modulated_corner(p, 1.0, 0.1, drift_kN_per_s);
  };
  expect_drift_rule("modulation rule", run);
}

// The lost rules judge a drive only once its torque filters have settled (three filter time
// constants since their first sample): at a start or a rejoin the acceleration is unknown and the
// need starts at the load alone. A drive pulled back by its load at -4 rev/s, faster than the
// motor's 1.4 A holding back explains (as the realtime system test
// SystemNetns.CornerLinkDownIsDetectedAndTheCornerRejoins saw an outage's own release when the
// link returned): named lost once settled, not in the first 35 ms.
TEST(FaultMonitor, TheLostRulesWaitForTheirFiltersToSettle) {
  const MonitorParams p = noiseless();
  const SampleCheck ok;
  auto run = [&](int settled_samples) {
    FaultMonitor m(p, Target::FL);
    std::uint64_t k = 0;
    double x = 3.0;
    for (int i = 0; i < settled_samples; ++i, ++k) {  // a hold: the current carries the load
      auto r = at(k + 1, 0.001 * (k + 1), x, 17.5);
      r.speed_rev_per_s = 1e-3 * static_cast<double>(k % 3);
      r.motor_current_A = 17.5 * p.Nm_per_kN / p.torque_per_A_Nm;
      m.update(r, ok, nullptr, 17.5, r.time_s);
    }
    double v = -3.7;
    for (int i = 0; i < 35; ++i, ++k) {  // backing off faster than the held-back torque explains
      v -= 0.043;
      x += v * 0.001;
      auto r = at(k + 1, 0.001 * (k + 1), x, 17.5);
      r.speed_rev_per_s = v;
      r.motor_current_A = 0.38 / p.torque_per_A_Nm;
      m.update(r, ok, nullptr, 17.5, r.time_s);
    }
    return m.diagnosis(Part::Actuator);
  };
  { const auto d0 = run(0); EXPECT_FALSE(d0.present) << to_string(d0.finding) << " at " << d0.detected_s << " onset " << d0.onset_s; }
  EXPECT_EQ(run(40).finding, Finding::ActuatorLost);
}

// Samples lost between two usable ones (an outage whose blocks came through one at a time, no
// rejoin) break the torque rules' filters and persistence: a suspicion from one block is not
// confirmed by the first sample of the next, 0.28 s later (realtime system test
// SystemNetns.CornerLinkDownIsDetectedAndTheCornerRejoins). Without the gap it is.
TEST(FaultMonitor, TheTorqueRulesStartAgainAfterLostSamples) {
  const MonitorParams p = noiseless();
  const SampleCheck ok;
  // The transient of the test above after a settled hold, with `gap_s` before transient sample
  // `gap_at`; returns the transient sample at which the actuator is first named (-1: never).
  auto run = [&](int gap_at, double gap_s) {
    FaultMonitor m(p, Target::FL);
    std::uint64_t seq = 0;
    double t = 0.0, x = 3.0, v = -3.7;
    for (int i = 0; i < 40; ++i) {
      t += 0.001;
      auto r = at(++seq, t, x, 17.5);
      r.speed_rev_per_s = 1e-3 * static_cast<double>(i % 3);
      r.motor_current_A = 17.5 * p.Nm_per_kN / p.torque_per_A_Nm;
      m.update(r, ok, nullptr, 17.5, t);
    }
    for (int i = 0; i < 60; ++i) {
      const double dt = i == gap_at ? gap_s : 0.001;
      t += dt;
      seq += static_cast<std::uint64_t>(std::lround(dt / 0.001));
      // After the gap the drive reverses at 40 A, as the corner did when its link came back:
      // healthy (the acceleration carries the torque), but its first sample, with the
      // acceleration unknown, looks lost.
      const bool reversing = gap_at >= 0 && i >= gap_at;
      v += reversing ? 0.57 : -0.043;
      x += v * 0.001;
      auto r = at(seq, t, x, reversing ? 6.6 : 17.5);
      r.speed_rev_per_s = v;
      r.motor_current_A = reversing ? 40.0 : 0.38 / p.torque_per_A_Nm;
      m.update(r, ok, nullptr, r.force_kN, t);
      if (m.diagnosis(Part::Actuator).present) return i;
    }
    return -1;
  };
  const int named_at = run(-1, 0.0);
  ASSERT_GE(named_at, 5);
  // The gap 3 samples before that, the suspicion 12 ms into its 15: not named at all.
  EXPECT_EQ(run(named_at - 3, 0.28), -1);
}

namespace {

// 100 samples of a drive holding 20 kN at 4 rev with a live resolver (its reading moves by its
// noise) and 3 A: the unpowered-hold tests' start, before the resolver freezes.
void hold_live_at_20kN(FaultMonitor& m, std::uint64_t& seq, double& t) {
  const SampleCheck ok;
  for (int k = 0; k < 100; ++k) {
    t += 0.001;
    auto r = at(++seq, t, 4.0 + 2e-5 * (k % 3), 20.0 + 0.01 * (k % 2));
    r.speed_rev_per_s = 1e-3 * (k % 5);
    r.motor_current_A = 3.0;
    m.update(r, ok, nullptr, r.force_kN, t);
  }
}

}  // namespace

// A resolver that freezes while its drive holds 20 kN leaves the motor without current: the
// clamp force can stay or fall (the load drives the spindle back), never rise. So a load cell
// that rises by more than unpowered_kN from the level it settled at names a load-cell offset
// (issue 14, tuning seed 1401 run 394); a fall, a rotor frozen at speed (it coasts on, the force
// rising), a current the corner still drives, or the rule off: nothing on the load cell.
TEST(FaultMonitor, AHeldDriveWithoutCurrentCannotRaiseItsLoadCell) {
  const MonitorParams shipped;  // the frozen-resolver rule names the resolver 20 samples in
  const SampleCheck ok;
  // 100 live samples, then the resolver frozen at `speed` with the motor at `current_A`; after
  // 100 frozen samples the load cell moves by `change_kN` over 50 ms and stays there.
  auto run = [&](double speed, double current_A, double change_kN, const MonitorParams& p) {
    FaultMonitor m(p, Target::RL);
    std::uint64_t seq = 0;
    double t = 0.0;
    hold_live_at_20kN(m, seq, t);
    for (int k = 0; k < 400; ++k) {
      t += 0.001;
      const double moved = change_kN * std::clamp((k - 100) / 50.0, 0.0, 1.0);
      auto r = at(++seq, t, 4.0, 20.0 + 0.01 * (k % 2) + moved);
      r.speed_rev_per_s = speed;
      r.motor_current_A = current_A;
      m.update(r, ok, nullptr, r.force_kN, t);
    }
    EXPECT_EQ(m.diagnosis(Part::Resolver).finding, Finding::ResolverStuck);
    return m.diagnosis(Part::LoadCell);
  };
  const auto rise = run(0.0, 0.0, 1.0, shipped);
  EXPECT_TRUE(rise.present);
  EXPECT_EQ(rise.finding, Finding::LoadCellOffset);
  EXPECT_FALSE(run(0.0, 0.0, -3.0, shipped).present);  // the load drives the spindle back
  EXPECT_FALSE(run(20.0, 0.0, 1.0, shipped).present);  // frozen at speed: the rotor coasts on
  EXPECT_FALSE(run(0.0, 5.0, 1.0, shipped).present);   // a current: not the corner's frozen-resolver stop
  MonitorParams off = shipped;
  off.unpowered_hold = false;
  EXPECT_FALSE(run(0.0, 0.0, 1.0, off).present);
}

// A resolver that freezes while the loop accelerates its drive (frozen at 0.39 rev/s, 19 A for
// 25 ms more until the corner cuts the current) leaves a rotor that coasts on unseen: at 20 kN the
// bound (19 A x 0.27 Nm/A less 0.8 Nm of load, over 2 pi 3e-3 kg m^2, and the drive's friction: 5.84 rev/s at the cut; the load and the
// drive's friction stop it in about 0.13 s) keeps the unpowered-hold rule off while the clamp
// force rises 0.6 kN; a +1 kN load-cell step after the coast is still named. Without the bound the
// coast's rise is a load-cell offset (issue 14, twenty-fourth session, tuning seed 1401 run 341).
TEST(FaultMonitor, AnUnpoweredHoldAllowsTheCoastOfARotorThatWasAcceleratingWhenTheResolverFroze) {
  const MonitorParams shipped;
  const SampleCheck ok;
  // 100 live samples at 20 kN, then the resolver frozen at 0.39 rev/s with 19 A for 25 samples
  // and 0 A after; the clamp force rises 0.6 kN over 100 ms from the cut; `step_kN` at 450 ms.
  auto run = [&](double step_kN, const MonitorParams& p, double* bound_at_cut) {
    FaultMonitor m(p, Target::RL);
    std::uint64_t seq = 0;
    double t = 0.0;
    hold_live_at_20kN(m, seq, t);
    for (int k = 0; k < 600; ++k) {
      t += 0.001;
      const double coast_kN = 0.6 * std::clamp((k - 25) / 100.0, 0.0, 1.0);
      auto r = at(++seq, t, 4.0, 20.0 + 0.01 * (k % 2) + coast_kN + (k >= 450 ? step_kN : 0.0));
      r.speed_rev_per_s = 0.39;
      r.motor_current_A = k < 25 ? 19.0 : 0.0;
      m.update(r, ok, nullptr, r.force_kN, t);
      if (k == 25 && bound_at_cut != nullptr) *bound_at_cut = m.unpowered_forward_speed_bound_rev_per_s();
    }
    EXPECT_EQ(m.diagnosis(Part::Resolver).finding, Finding::ResolverStuck);
    return m.diagnosis(Part::LoadCell);
  };
  double bound = 0.0;
  EXPECT_FALSE(run(0.0, shipped, &bound).present);
  EXPECT_NEAR(bound, 0.39 + 25 * 0.001 * (19.0 * 0.27 - 0.0398 * 19.0) / (2 * std::numbers::pi * 3e-3), 0.5);
  std::printf("the forward speed bound at the cut: %.2f rev/s\n", bound);
  const auto step = run(1.0, shipped, nullptr);
  EXPECT_TRUE(step.present);
  EXPECT_EQ(step.finding, Finding::LoadCellOffset);
  EXPECT_GE(step.onset_s, 0.1 + 0.45 - 1e-6);  // the step's, not the coast's
  MonitorParams off = shipped;
  off.unpowered_coast_bound = false;
  const auto coast = run(0.0, off, nullptr);
  EXPECT_TRUE(coast.present);
  EXPECT_EQ(coast.finding, Finding::LoadCellOffset);
}
