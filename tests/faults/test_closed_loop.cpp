// Behavioural targets of issue 5 in the in-memory closed loop (docs/faults.md, "Measured").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <limits>

#include "closed_loop.hpp"

using namespace bbw::faults;
using namespace bbw::faults::test;

namespace {

FaultScenario load(const std::string& rel) { return load_fault_scenario(source_path(rel)); }

// A corner's actuator diagnosis at the end of a closed-loop run.
const Diagnosis& actuator(const LoopResult& r, std::size_t corner) {
  return r.diagnoses[corner * 5 + static_cast<std::size_t>(Part::Actuator)];
}

// ... and its load cell's.
const Diagnosis& load_cell(const LoopResult& r, std::size_t corner) {
  return r.diagnoses[corner * 5 + static_cast<std::size_t>(Part::LoadCell)];
}

// The calibrator started as configured, as when the older rules were made: the shipped caliper's
// range and elements, no key friction until its first fit, no load-dependent friction or play
// terms (calibrator_start.range_, elements_, friction_, load_friction_ and backlash_from_end_of_
// line), and the tracking rules counting only fitted friction. From the caliper's own start
// several of the residuals those rules were made for no longer arise.
void start_as_configured(MonitorParams& m) {
  m.calibrator_range_from_eol = false;
  m.calibrator_elements_from_eol = false;
  m.calibrator_friction_from_eol = false;
  m.calibrator_load_friction_from_eol = false;
  m.calibrator_backlash_from_eol = false;
  m.tracking_friction_as_subtracted = false;
}

// The campaign scenarios hold a stop from 10 s to 13 s and inject at 11 s.
constexpr double kFaultAt = 11.0;
constexpr double kStopEnd = 13.0;

}  // namespace

TEST(ClosedLoop, EveryFaultFreeVehicleScenarioRaisesNoFault) {
  // Every scenario with a pedal demand and the four vehicle corners, in config/scenarios/.
  std::size_t runs = 0;
  for (const char* rel : {"config/scenarios/vehicle_stop.yaml", "config/scenarios/faults/fault_free_stop.yaml"}) {
    const auto fs = load(rel);
    ASSERT_TRUE(fs.faults.empty());
    const auto r = run_closed_loop(fs, default_options());
    for (std::size_t k = 0; k < r.diagnoses.size(); ++k) {
      if (r.diagnoses[k].present) ADD_FAILURE() << rel << ": " << to_string(r.diagnoses[k].finding) << " at " << r.diagnoses[k].detected_s;
    }
    ++runs;
  }
  EXPECT_EQ(runs, 2u);
}

TEST(ClosedLoop, FaultFreeStopRaisesNoFault) {
  const auto fs = load("config/scenarios/faults/fault_free_stop.yaml");
  const auto r = run_closed_loop(fs, default_options());
  for (std::size_t i = 0; i < kCorners; ++i) {
    std::printf("corner %zu: fits %llu, fed %llu\n", i, static_cast<unsigned long long>(r.fits[i]),
                static_cast<unsigned long long>(r.calibrator_samples[i]));
    for (std::size_t p = 0; p < 5; ++p) {
      const auto& d = r.diagnoses[i * 5 + p];
      if (d.present) std::printf("  raised %s at %.3f s\n", to_string(d.finding), d.detected_s);
    }
  }
  double worst = 0.0, worst_t = 0.0;
  for (const auto& p : r.periods) {
    for (std::size_t i = 0; i < kCorners; ++i) {
      const double e = std::abs(p.estimate_kN[i] - p.true_kN[i]);
      if (p.time_s > 10.0 && e > worst) {
        worst = e;
        worst_t = p.time_s;
      }
    }
  }
  std::array<double, kCorners> rmax{}, nmax{}, rhold{}, cmax{};
  for (const auto& p : r.periods) {
    for (std::size_t i = 0; i < kCorners; ++i) {
      if (p.time_s > 5.0 && std::isfinite(p.residual_kN[i])) rmax[i] = std::max(rmax[i], std::abs(p.residual_kN[i]));
      nmax[i] = std::max(nmax[i], p.noise_kN[i]);
      if (p.time_s > 5.0 && std::isfinite(p.residual_change_kN[i])) cmax[i] = std::max(cmax[i], std::abs(p.residual_change_kN[i]));
      if (p.time_s > 10.0 && std::isfinite(p.residual_kN[i])) rhold[i] = std::max(rhold[i], std::abs(p.residual_kN[i]));
    }
  }
  for (std::size_t i = 0; i < kCorners; ++i) std::printf("corner %zu: max |residual| after 5 s %.3f kN, after 10 s %.3f kN; max |change| after 5 s %.3f kN; max large-step share %.3f\n", i, rmax[i], rhold[i], cmax[i], nmax[i]);
  std::printf("worst estimate error after 10 s: %.3f kN at %.3f s\n", worst, worst_t);
  EXPECT_EQ(r.faults_raised(), 0u);
}

namespace {

const std::vector<std::string>& campaign() {
  static const std::vector<std::string> names = {
      "load_cell_bias", "load_cell_drift", "load_cell_stuck", "load_cell_noise_burst", "load_cell_dropout",
      "resolver_offset", "resolver_stuck", "actuator_torque_loss", "actuator_total_loss", "actuator_seized", "network_silence",
      "network_delay", "process_kill", "ccu_kill"};
  return names;
}

}  // namespace


namespace {

FaultScenario with_fault(const FaultSpec& f) {
  auto fs = load("config/scenarios/faults/fault_free_stop.yaml");
  fs.faults.faults.push_back(f);
  check_schedule(fs.scenario, fs.faults);
  return fs;
}

FaultSpec fault(Target c, Part p, FaultType t, double at_s = kFaultAt) {
  FaultSpec f;
  f.at_s = at_s;
  f.target = c;
  f.part = p;
  f.type = t;
  return f;
}

constexpr std::array<Target, kCorners> kAll = {Target::FL, Target::FR, Target::RL, Target::RR};

}  // namespace

TEST(ClosedLoop, EveryCampaignScenarioIsDetectedAndIsolatedWithNoOtherFinding) {
  std::printf("%-24s %-6s %-10s %-12s %9s  %-22s %-7s %s\n", "scenario", "corner", "part", "type", "latency", "diagnosis",
              "correct", "delivered");
  for (const auto& n : campaign()) {
    const auto fs = load("config/scenarios/faults/" + n + ".yaml");
    const auto r = run_closed_loop(fs, default_options());
    const FaultSpec& f = fs.faults.faults.at(0);
    if (f.target == Target::CCU) {
      EXPECT_EQ(r.faults_raised(), 0u) << n;  // the CCU's death is handled by the corners
      continue;
    }
    ASSERT_EQ(r.outcomes.size(), 1u);
    const auto& o = r.outcomes[0];
    std::printf("%-24s %-6s %-10s %-12s %7.1f ms  %-22s %-7s %.3f\n", n.c_str(), to_string(o.fault.target),
                to_string(o.fault.part), to_string(o.fault.type), o.detected ? o.latency_ms : -1.0,
                to_string(o.diagnosis), o.correct ? "yes" : "no", o.delivered_share);
    EXPECT_TRUE(o.detected) << n;
    EXPECT_TRUE(o.correct) << n << ": " << to_string(o.diagnosis);
    EXPECT_GE(o.latency_ms, 0.0) << n;
    const std::size_t slot = *corner_slot(f.target);
    for (std::size_t i = 0; i < kCorners; ++i) {
      for (std::size_t p = 0; p < 5; ++p) {
        const auto& d = r.diagnoses[i * 5 + p];
        const bool expected_corner = i == slot;
        const bool kill_link = f.type == FaultType::Kill && static_cast<Part>(p) == Part::Network;
        if (d.present && !(expected_corner && (static_cast<Part>(p) == f.part || kill_link))) {
          ADD_FAILURE() << n << ": corner " << i << " also raised " << to_string(d.finding) << " at " << d.detected_s;
        }
      }
    }
  }
}

TEST(ClosedLoop, LoadCellBiasOfOneKilonewtonIsIsolatedWithin100msAndTheCurveEstimateIsWithinHalfAKilonewton) {
  std::printf("%-6s %8s %10s %14s\n", "corner", "bias_kN", "latency", "max |error|");
  for (Target c : kAll) {
    for (double bias : {1.0, -1.0, 2.0, -2.0}) {
      auto f = fault(c, Part::LoadCell, FaultType::Bias);
      f.bias_kN = bias;
      const auto r = run_closed_loop(with_fault(f), default_options());
      ASSERT_EQ(r.outcomes.size(), 1u);
      const auto& o = r.outcomes[0];
      const std::size_t i = *corner_slot(c);
      double worst = 0.0;
      for (const auto& p : r.periods) {
        if (p.time_s >= o.detected_s + 0.05 && p.time_s <= kStopEnd) {
          worst = std::max(worst, std::abs(p.estimate_kN[i] - p.true_kN[i]));
        }
      }
      std::printf("%-6s %8.1f %7.1f ms %11.3f kN\n", to_string(c), bias, o.latency_ms, worst);
      EXPECT_TRUE(o.detected && o.correct) << to_string(c) << " " << bias;
      EXPECT_EQ(o.diagnosis, Finding::LoadCellOffset);
      EXPECT_LE(o.latency_ms, 100.0) << to_string(c) << " " << bias;
      EXPECT_LT(worst, 0.5) << to_string(c) << " " << bias;
      EXPECT_EQ(r.faults_raised(), 1u) << to_string(c) << " " << bias;
    }
  }
}

TEST(ClosedLoop, OneCornerLostDuringAStopTotalBackAbove90PercentWithin100ms) {
  // Remaining limits: 3 x 40 kN = 120 kN, more than the 66.7 kN demanded at 0.5.
  // A killed corner's plant dies with its process (as over DDS: it lived in the corner process),
  // so it brakes 0 from the kill on: the worst case (an unpowered ball screw would be back-driven
  // over ~0.3 s). The others must make up its whole share within 100 ms.
  std::printf("%-6s %-11s %10s %14s %18s\n", "corner", "loss", "detected", "recovered", "lowest share");
  for (Target c : kAll) {
    for (FaultType t : {FaultType::TotalLoss, FaultType::Kill}) {
      const auto f = fault(c, t == FaultType::Kill ? Part::Process : Part::Actuator, t);
      const auto fs = with_fault(f);
      const auto r = run_closed_loop(fs, default_options());
      const double rec = recovery_time_s(r, 0.9, kFaultAt, kStopEnd, 120.0);
      double lowest = 1e9;
      for (const auto& p : r.periods) {
        if (p.time_s >= kFaultAt && p.time_s <= kStopEnd) lowest = std::min(lowest, p.delivered_total_kN / p.demand_total_kN);
      }
      std::printf("%-6s %-11s %7.1f ms %11.1f ms %17.3f\n", to_string(c), to_string(t), r.outcomes[0].latency_ms,
                  1e3 * (rec - kFaultAt), lowest);
      EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct) << to_string(c) << " " << to_string(t);
      ASSERT_GT(rec, 0.0) << to_string(c) << " " << to_string(t);
      EXPECT_LE(rec - kFaultAt, 0.100 + 1e-9) << to_string(c) << " " << to_string(t);
      // Without redistribution the same loss leaves the total short of 90 %.
      auto no = default_options();
      no.redistribute = false;
      const auto base = run_closed_loop(fs, no);
      EXPECT_LT(recovery_time_s(base, 0.9, kFaultAt, kStopEnd, 120.0), 0.0) << to_string(c) << " " << to_string(t);
    }
  }
}

// A seized actuator (FL jams at the 24 kN peak at 9.0 s) keeps its force when told to release.
// The torque balance first finds the actuator lost (current without motion); once a release is
// commanded and the brake does not move back, the finding becomes actuator_not_releasing. From
// then on FL's held force counts on the front axle: FR is asked for less, so during the stop
// held 10-13 s the total stays near the demand; counting FL as braking 0 (the reaction to a
// lost actuator) over-brakes the front axle by FL's held force.
TEST(ClosedLoop, ASeizedActuatorIsNamedNotReleasingAndItsHeldForceIsCounted) {
  const auto fs = load("config/scenarios/faults/actuator_seized.yaml");
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  const auto& o = r.outcomes[0];
  EXPECT_TRUE(o.detected && o.correct);
  EXPECT_EQ(o.diagnosis, Finding::ActuatorNotReleasing);
  const Diagnosis& d = actuator(r, 0);
  ASSERT_TRUE(d.present);
  EXPECT_EQ(d.finding, Finding::ActuatorNotReleasing);
  EXPECT_GE(d.finding_s, d.detected_s);
  auto no_held = default_options();
  no_held.count_held_force = false;
  const auto base = run_closed_loop(fs, no_held);
  auto front_excess = [](const LoopResult& res, const bbw::scenario::Scenario& s) {
    double worst = 0.0, held = 0.0;  // worst: largest |front total - front demand|
    for (const auto& p : res.periods) {
      if (p.time_s < 10.3 || p.time_s > kStopEnd) continue;
      const double front_demand = s.demand->front_share * p.demand_total_kN;
      worst = std::max(worst, std::abs(p.true_kN[0] + p.true_kN[1] - front_demand));
      held = std::max(held, p.true_kN[0]);
    }
    return std::pair{worst, held};
  };
  const auto [excess, held] = front_excess(r, fs.scenario);
  const auto [base_excess, base_held] = front_excess(base, fs.scenario);
  std::printf("seized FL: first detected %.1f ms after the seizure (%s), named not releasing %.1f ms after it;\n"
              "front axle off its demand in the held stop by at most %.3f kN counting FL's held %.2f kN, %.3f kN not counting it\n",
              o.latency_ms, "actuator", 1e3 * (d.finding_s - fs.faults.faults[0].at_s), excess, held, base_excess);
  EXPECT_GT(held, 5.0);                 // the brake really held its force
  EXPECT_GT(base_excess, 0.8 * held);   // without counting it, the front over-brakes by about that
  EXPECT_LT(excess, 1.0);               // counting it, FR makes up only the rest
  EXPECT_LT(d.finding_s - fs.faults.faults[0].at_s, 1.0);
}

// A drive that seizes in the middle of a held stop keeps its force where it is commanded, so no
// rule that waits for motion sees it before the release. The corners' actuator test in holds
// (back and forth by the hold's current and 1.5 A more, 3 ms each, every 15 ms) gives the
// monitor a rotor that does not answer: actuator_lost within issue 14's 50 ms latency goal for
// loss and stuck faults (two unanswered tests), long before the release. The healthy corners answer, FR with a backlash in its gear
// too (a gear held against its flank moves back when the current changes sign).
TEST(ClosedLoop, ALoadCellBiasDuringASlowFirstApplyIsFoundWhileTheRotorMoves) {
  const auto fs = load("config/scenarios/faults/load_cell_bias_while_applying.yaml");
  const double at_s = fs.faults.faults.at(0).at_s;
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  const auto& o = r.outcomes[0];
  EXPECT_TRUE(o.detected && o.correct);
  EXPECT_EQ(o.diagnosis, Finding::LoadCellOffset);
  EXPECT_LT(o.latency_ms, 20.0);
  EXPECT_EQ(r.faults_raised(), 1u);  // healthy corners with a backlash, viscous friction, a delay: nothing
  auto opts = default_options();
  opts.monitor.step_moving = false;
  const auto base = run_closed_loop(fs, opts);
  ASSERT_EQ(base.outcomes.size(), 1u);
  // Without the moving step rule: the end-of-line band, or the still rule once the apply stops.
  EXPECT_TRUE(!base.outcomes[0].detected || base.outcomes[0].latency_ms > 100.0) << base.outcomes[0].latency_ms;
  std::printf("bias while applying at %.1f s: found %.0f ms later with the moving step rule, %s without it\n", at_s,
              o.latency_ms, base.outcomes[0].detected ? (std::to_string(base.outcomes[0].latency_ms) + " ms").c_str() : "not");
}

TEST(ClosedLoop, ADriveThatSeizesInAHoldIsFoundByTheActuatorTestBeforeTheRelease) {
  const auto fs = load("config/scenarios/faults/actuator_seized_in_hold.yaml");
  ASSERT_GT(fs.scenario.controller.hold_test_current_A, 0.0);
  const double seized_at_s = fs.faults.faults.at(0).at_s;
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct);
  EXPECT_EQ(r.outcomes[0].diagnosis, Finding::ActuatorNotReleasing);  // actuator_lost, refined at the release
  const Diagnosis& fl = actuator(r, 0);
  ASSERT_TRUE(fl.present);
  EXPECT_GT(fl.detected_s, seized_at_s);
  EXPECT_LT(fl.detected_s - seized_at_s, 0.05);
  for (std::size_t c = 1; c < kCorners; ++c) {
    EXPECT_FALSE(actuator(r, c).present) << "corner " << c;
  }
  auto off = fs;
  off.scenario.controller.hold_test_current_A = 0.0;
  const auto base = run_closed_loop(off, default_options());
  const Diagnosis& fl_off = actuator(base, 0);
  ASSERT_TRUE(fl_off.present);
  // Without it only the seized rule's current ramp (the loop's integrators wind up against the
  // rotor as the key friction relaxes) finds it, outside the scorer's 0.5 s.
  EXPECT_GT(fl_off.detected_s - seized_at_s, 0.5);
  EXPECT_LT(fl.detected_s, fl_off.detected_s);
  std::printf("seized in a hold at %.1f s: found %.0f ms later with the actuator test, %.0f ms later without it\n",
              seized_at_s, 1e3 * (fl.detected_s - seized_at_s), 1e3 * (fl_off.detected_s - seized_at_s));
}

// Issue 14, thirteenth session: a 60 % torque loss in a held stop. The drive holds the force with
// little current (and the motor side of FL's backlash settles slowly within the gap), so only
// the actuator test sees it: the rotor answers about 0.4 of a healthy rotor, too strongly for a
// dead drive and too weakly for a healthy one. The weak-answer rule names it a torque loss (the
// corner stays in use); without it nothing is named here. Two weak answers below the unanswered
// threshold no longer name a lost actuator unless their mean is a dead drive's (tuning seed 1403
// runs 532, 580, 86: 67-74 % losses named actuator_lost). A total loss at the same moment is
// still lost.
TEST(ClosedLoop, AHalfLostMotorInAHoldIsATorqueLossNotALostActuator) {
  const auto fs = load("config/scenarios/faults/actuator_torque_loss_in_hold.yaml");
  ASSERT_GT(fs.scenario.controller.hold_test_current_A, 0.0);
  const double at_s = fs.faults.faults.at(0).at_s;
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct);
  EXPECT_EQ(r.outcomes[0].diagnosis, Finding::ActuatorTorqueLoss);
  const Diagnosis fl = actuator(r, 0);
  ASSERT_TRUE(fl.present);
  EXPECT_EQ(fl.finding, Finding::ActuatorTorqueLoss);
  EXPECT_LT(fl.detected_s - at_s, 0.3);
  EXPECT_EQ(r.faults_raised(), 1u);  // the healthy corners (backlash; viscous friction at 54 C) raise nothing

  auto opts = default_options();
  opts.monitor.test_pulse_weak_count = 0;
  const auto base = run_closed_loop(fs, opts);
  ASSERT_EQ(base.outcomes.size(), 1u);
  EXPECT_FALSE(base.outcomes[0].detected);

  // The healthy answer is learnt per corner: with the drive's nominal answer set far too low
  // (0.3 instead of about 0.69), the learnt one still finds the loss as fast; never learning, it is
  // found only once the answers have sunk further (639 ms) or not at all.
  auto low = default_options();
  low.monitor.test_pulse_healthy_ratio = 0.3;
  const auto learnt = run_closed_loop(fs, low);
  EXPECT_TRUE(learnt.outcomes[0].detected && learnt.outcomes[0].correct);
  EXPECT_LT(learnt.outcomes[0].latency_ms, 300.0);
  EXPECT_EQ(learnt.faults_raised(), 1u);
  low.monitor.test_pulse_learn_count = 1000000;
  const auto never = run_closed_loop(fs, low);
  EXPECT_TRUE(!never.outcomes[0].detected || never.outcomes[0].latency_ms > 500.0) << never.outcomes[0].latency_ms;

  // Once named, the drive is judged as the weaker drive it is: a 67 % loss stays a torque loss
  // through the release (the lost rules look for a further loss); judged against the healthy
  // drive, and with a pull judged without its fraction (torque.unexplained_pull_fraction), it is
  // named lost at the release, when the loop drives the weak motor back. The pull's fraction alone
  // keeps it a torque loss there too (a pull 3 times its need is not in vain).
  auto weaker = fs;
  weaker.faults.faults[0].torque_loss_percent = 67.0;
  const auto kept = run_closed_loop(weaker, default_options());
  EXPECT_EQ(actuator(kept, 0).finding, Finding::ActuatorTorqueLoss);
  auto healthy_model = default_options();
  healthy_model.monitor.torque_loss_rescales_drive = false;
  EXPECT_EQ(actuator(run_closed_loop(weaker, healthy_model), 0).finding, Finding::ActuatorTorqueLoss);
  healthy_model.monitor.unexplained_pull_fraction = false;
  const auto upgraded = run_closed_loop(weaker, healthy_model);
  EXPECT_EQ(actuator(upgraded, 0).finding, Finding::ActuatorLost);
  EXPECT_GT(actuator(upgraded, 0).finding_s, 6.0);  // at the release (6.0-6.5 s)

  auto dead = fs;
  dead.faults.faults[0].type = FaultType::TotalLoss;
  const auto lost = run_closed_loop(dead, default_options());
  ASSERT_EQ(lost.outcomes.size(), 1u);
  EXPECT_TRUE(lost.outcomes[0].detected && lost.outcomes[0].correct);
  EXPECT_TRUE(actuator(lost, 0).finding == Finding::ActuatorLost || actuator(lost, 0).finding == Finding::ActuatorNotReleasing)
      << to_string(actuator(lost, 0).finding);
  // At most one test later than with the lost rule's mean left out: here the first unanswered
  // pulse straddles the loss (its answer partly a healthy rotor's), so the pair's mean is above
  // test_pulse_lost_mean_ratio and the third pulse decides (51 instead of 30 ms).
  auto any_mean = default_options();
  any_mean.monitor.test_pulse_lost_mean_ratio = any_mean.monitor.test_pulse_answer_ratio;
  const auto lost_before = run_closed_loop(dead, any_mean);
  EXPECT_LE(actuator(lost, 0).detected_s, actuator(lost_before, 0).detected_s + 0.0215);
  EXPECT_LT(actuator(lost, 0).detected_s - at_s, 0.06);
  std::printf("60 %% torque loss in a hold at %.1f s: %s %.0f ms later; without the weak-answer rule: %s; a total loss: %.0f ms (%.0f ms without the mean)\n",
              at_s, to_string(fl.finding), 1e3 * (fl.detected_s - at_s),
              base.outcomes[0].detected ? to_string(base.outcomes[0].diagnosis) : "missed",
              1e3 * (actuator(lost, 0).detected_s - at_s), 1e3 * (actuator(lost_before, 0).detected_s - at_s));
}

// Issue 14, thirteenth session: a drive that seizes in a 37 kN hard stop on a hot caliper with a
// backlash (tuning seed 1401 run 280). Its answers to the actuator test scatter about 0 by up to
// +-0.17, so two unanswered pulses in a row come late; the mean of the latest half of the last 8
// answers is a dead drive's sooner. Named lost (never a torque loss: the weak-answer rule waits
// while the recent answers are a dead drive's), and sooner than without the rule.
TEST(ClosedLoop, ADeadDrivesScatteredAnswersAtHighLoadAreLostByTheirRecentMean) {
  const auto fs = load("config/scenarios/faults/actuator_seized_in_hard_stop_hot.yaml");
  const double at_s = fs.faults.faults.at(0).at_s;
  const auto fr = [](const LoopResult& r) { return actuator(r, 1); };
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct);  // correct: no torque loss named first
  ASSERT_TRUE(fr(r).present);
  EXPECT_LT(fr(r).detected_s - at_s, 0.1);
  EXPECT_EQ(r.faults_raised(), 1u);
  auto opts = default_options();
  opts.monitor.test_pulse_weak_count = 0;
  const auto base = run_closed_loop(fs, opts);
  ASSERT_TRUE(fr(base).present);
  EXPECT_GT(fr(base).detected_s, fr(r).detected_s + 0.02);
  std::printf("seized at 37 kN, hot, backlash: lost %.0f ms later; %.0f ms without the recent answers' mean\n",
              1e3 * (fr(r).detected_s - at_s), 1e3 * (fr(base).detected_s - at_s));
}

TEST(ClosedLoop, CorruptSamplesNeverChangeACommandOrAnEstimate) {
  const auto fs = load("config/scenarios/faults/fault_free_stop.yaml");
  const auto clean = run_closed_loop(fs, default_options());
  auto o = default_options();
  std::uint64_t added = 0;
  o.deliver = [&](std::size_t corner, const bbw::msg::MeasurementSample& r, std::vector<bbw::msg::MeasurementSample>& out) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    out.push_back(r);
    if (r.seq() % 7 != static_cast<std::uint64_t>(corner)) return;
    bbw::msg::MeasurementSample bad = r;
    switch ((r.seq() / 7) % 6) {
      case 0: bad.position_rev(nan); break;
      case 1: bad.force_internal_kN(std::numeric_limits<double>::infinity()); break;
      case 2: bad.force_internal_kN(1e4); break;
      case 3: bad.force_internal_kN(r.force_internal_kN() + 5.0); break;  // the same sequence number again
      case 4:
        bad.seq(r.seq() > 3 ? r.seq() - 3 : 0);  // backwards
        bad.force_internal_kN(0.0);
        break;
      case 5: bad.motor_current_A(nan); break;
    }
    out.push_back(bad);
    ++added;
  };
  const auto dirty = run_closed_loop(fs, o);
  ASSERT_EQ(clean.periods.size(), dirty.periods.size());
  for (std::size_t k = 0; k < clean.periods.size(); ++k) {
    for (std::size_t i = 0; i < kCorners; ++i) {
      ASSERT_EQ(clean.periods[k].command_kN[i], dirty.periods[k].command_kN[i]) << k;
      ASSERT_EQ(clean.periods[k].true_kN[i], dirty.periods[k].true_kN[i]) << k;
      const double a = clean.periods[k].estimate_kN[i], b = dirty.periods[k].estimate_kN[i];
      ASSERT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << k;
    }
  }
  std::uint64_t rejected = 0;
  for (std::size_t i = 0; i < kCorners; ++i) {
    rejected += dirty.guard_rejected[i];
    EXPECT_EQ(dirty.calibrator_samples[i], clean.calibrator_samples[i]);
  }
  EXPECT_GT(added, 1000u);
  EXPECT_EQ(rejected, added);
  EXPECT_EQ(dirty.faults_raised(), 0u);
}

TEST(ClosedLoop, ACcuKillLeavesEveryCornerBrakingAtHeldThenDefaultForce) {
  const auto fs = load("config/scenarios/faults/ccu_kill.yaml");
  const auto o = default_options();
  const auto r = run_closed_loop(fs, o);
  const double default_kN = o.watchdog.default_clamp_force_kN;
  for (const auto& p : r.periods) {
    if (p.time_s < kFaultAt + 0.01) continue;
    ASSERT_FALSE(p.ccu_alive);
    for (std::size_t i = 0; i < kCorners; ++i) {
      ASSERT_GE(p.applied_kN[i], default_kN - 1e-9) << p.time_s;  // the stop held 13..20 kN > default
      if (p.time_s > kFaultAt + o.watchdog.timeout_s + o.watchdog.hold_s + 0.6) {
        ASSERT_NEAR(p.applied_kN[i], default_kN, 1e-9) << p.time_s;
        ASSERT_NEAR(p.true_kN[i], default_kN, 1.5) << p.time_s;  // still braking after the pedal release
      }
    }
  }
}

TEST(ClosedLoop, ARestartedCornerRejoinsWithItsLastGoodCurveAndNoSampleTwice) {
  const auto fs = load("config/scenarios/faults/process_kill.yaml");
  std::vector<std::uint64_t> seen_rr;
  auto o = default_options();
  o.deliver = [&](std::size_t corner, const bbw::msg::MeasurementSample& r, std::vector<bbw::msg::MeasurementSample>& out) {
    if (corner == 3) seen_rr.push_back(r.seq());
    out.push_back(r);
  };
  const auto r = run_closed_loop(fs, o);
  EXPECT_EQ(r.calibrator_restarts[3], 1u);
  EXPECT_EQ(r.guard_rejected[3], 0u);
  // 11000 samples before the kill at 11 s, then a new incarnation from 1 after the restart.
  ASSERT_GT(seen_rr.size(), 11000u);
  EXPECT_EQ(seen_rr[10999], 11000u);
  EXPECT_EQ(seen_rr[11000], 1u);
  EXPECT_EQ(seen_rr.size(), 11000u + 2500u);
  bool back = false;
  for (const auto& p : r.periods) {
    if (p.time_s > kFaultAt + 0.03 && p.time_s < kFaultAt + 0.5) {
      ASSERT_FALSE(p.available[3]) << p.time_s;
    }
    if (p.time_s > kFaultAt + 0.6 && p.time_s < kStopEnd) {
      back = back || p.available[3];
      ASSERT_LT(std::abs(p.estimate_kN[3] - p.true_kN[3]), 0.5) << p.time_s;
    }
  }
  EXPECT_TRUE(back);
  EXPECT_GT(recovery_time_s(r, 0.9, kFaultAt + 0.6, kStopEnd, 160.0), 0.0);
}

// Issue 14: after a correctly diagnosed resolver offset the estimate (load cell minus a friction
// followed from the load cell's own motion, never below 0) stays within 1 kN of the true force;
// with the friction frozen at the fault it was 2.1 kN off (a release, and a released brake).
TEST(ClosedLoopIssue14, AfterAResolverOffsetTheEstimateDoesNotUseTheResolver) {
  const auto r = run_closed_loop(load("config/scenarios/faults/resolver_offset.yaml"), default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  ASSERT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct);
  const std::size_t i = *corner_slot(r.outcomes[0].fault.target);
  double worst = 0.0;
  for (const auto& p : r.periods) {
    if (p.time_s >= r.outcomes[0].detected_s + 0.05 && std::isfinite(p.estimate_kN[i])) {
      worst = std::max(worst, std::abs(p.estimate_kN[i] - p.true_kN[i]));
    }
  }
  std::printf("resolver offset: worst |estimate - true| after the diagnosis %.3f kN\n", worst);
  EXPECT_LT(worst, 1.0);
}


// Issue 14: a calibrator stopped by a finding that later clears resumes. A 0.5 s fault of `part`
// on RL at 11 s is found; once the channel lives again the finding clears, the calibrator restarts
// once from the last good curve and is fed again, nothing else is raised, and the estimate is the
// calibrator's again: the worst |estimate - true| in (from_s, 13 s).
namespace {
double finding_clears_and_the_calibrator_resumes(Part part, FaultType type, double from_s) {
  auto f = fault(Target::RL, part, type);
  f.duration_s = 0.5;
  const auto r = run_closed_loop(with_fault(f), default_options());
  EXPECT_EQ(r.outcomes.size(), 1u);
  if (r.outcomes.size() != 1u) return 1e9;
  EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct);
  const auto& d = r.diagnoses[2 * 5 + static_cast<std::size_t>(part)];
  EXPECT_TRUE(d.present);
  EXPECT_FALSE(d.active) << "the finding cleared once the channel lived again";
  EXPECT_EQ(r.calibrator_restarts[2], 1u);
  EXPECT_EQ(r.faults_raised(), 1u);
  double worst = 0.0;
  for (const auto& p : r.periods) {
    if (p.time_s > from_s && p.time_s < 13.0) worst = std::max(worst, std::abs(p.estimate_kN[2] - p.true_kN[2]));
  }
  return worst;
}
}  // namespace

// The dropout's finding clears 0.2 s after the values are back. The calibrator's friction
// elements restart relaxed, so until the brake moves the estimate may be off by up to the key
// friction's width (1 kN).
TEST(ClosedLoopIssue14, AfterADropoutEndsTheCalibratorResumes) {
  const double worst = finding_clears_and_the_calibrator_resumes(Part::LoadCell, FaultType::Dropout, 11.8);
  std::printf("after the dropout: worst |estimate - true| in the held stop %.3f kN\n", worst);
  EXPECT_LT(worst, 1.0);
}

// A stuck resolver's finding clears once its speed has changed in 200 consecutive samples; the
// corner's residual and torque balance run again (a second fault after an intermittent stuck
// resolver was unseen while the finding latched: tune_b run 426, a torque loss).
TEST(ClosedLoopIssue14, AfterAStuckResolverLivesAgainTheCalibratorResumes) {
  const double worst = finding_clears_and_the_calibrator_resumes(Part::Resolver, FaultType::Stuck, 12.0);
  std::printf("after the stuck resolver: worst |estimate - true| from 12 to 13 s %.3f kN\n", worst);
  EXPECT_LT(worst, 1.0);
}

// After a load-cell finding on a corner not yet calibrated, the corner runs on its initial curve,
// which reads this caliper 24 % low; the torque balance's lost and torque-loss rules take that
// unmeasured load at the top of its plausible range (the end-of-line curve, the key friction's
// width, the curve's band). Taken as the curve says, a healthy drive decelerating at the end of
// an apply was named lost (tuning seed 1403 run 502).
TEST(ClosedLoopIssue14, AfterALoadCellFindingAHealthyDriveOnAnUncalibratedCurveIsNotNamed) {
  const auto fs = load("config/scenarios/faults/load_cell_bias_before_the_first_fit_then_apply.yaml");
  const auto rr = [](const LoopResult& r) { return actuator(r, 3); };
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct);
  EXPECT_FALSE(rr(r).present) << to_string(rr(r).finding) << " at " << rr(r).detected_s;
  EXPECT_EQ(r.faults_raised(), 1u);
  auto opts = default_options();
  opts.monitor.torque_lost_unmeasured_load_high = false;
  // (Left with the configured curve, the shipped caliper's, as when the rule was made: with this
  // caliper's own end-of-line curve, calibrator_start.initial_curve_from_end_of_line and
  // load_cell_lost.curve_from_end_of_line_beyond_data, the curve no longer reads it low.)
  opts.monitor.calibrator_initial_curve_from_eol = false;
  opts.monitor.lost_load_cell_curve_from_eol = false;
  const auto base = run_closed_loop(fs, opts);
  ASSERT_TRUE(base.outcomes[0].detected && base.outcomes[0].correct);
  ASSERT_TRUE(rr(base).present);  // the load as the curve says: a healthy drive named
  std::printf("load taken as the uncalibrated curve says: %s at %.3f s; at the top of its range: nothing\n",
              to_string(rr(base).finding), rr(base).detected_s);
}

namespace {

// Runs a one-fault scenario with the shipped monitor (with `common` applied to it) and again with
// `without` applied too: the first names the fault rightly within its window and raises nothing
// else, the second does not name it within its window. Prints both latencies.
void expect_named_in_window_only_with_the_rule(const std::string& file, const char* rule,
                                               const std::function<void(MonitorParams&)>& without,
                                               const std::function<void(MonitorParams&)>& common = [](MonitorParams&) {}) {
  const auto fs = load(file);
  auto shipped = default_options();
  common(shipped.monitor);
  const auto r = run_closed_loop(fs, shipped);
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct) << to_string(r.outcomes[0].diagnosis);
  EXPECT_EQ(r.faults_raised(), 1u);
  auto opts = shipped;
  without(opts.monitor);
  const auto base = run_closed_loop(fs, opts);
  ASSERT_EQ(base.outcomes.size(), 1u);
  EXPECT_FALSE(base.outcomes[0].detected);
  std::printf("with %s: named after %.0f ms; without: %s after %.0f ms (window %.0f ms)\n", rule, r.outcomes[0].latency_ms,
              to_string(base.outcomes[0].diagnosis), base.outcomes[0].diagnosis_latency_ms,
              1e3 * detection_window_s(fs.faults.faults[0]));
}

}  // namespace

// A load-cell drift in a held hard stop that the corner's loop follows by creeping back: the hold
// rule keeps its reference for hold_span_known_rev (0.3 rev) once the end-of-line friction model's
// state is known, and names the drift within its window (tuning seed 1408 run 466). Kept only
// within 0.1 rev (the span before the fifteenth session), the creep restarted the hold and threw
// away what the drift had moved: named after the release, past the window. With an end-of-line
// test accurate to 3 % (as shipped until the sixteenth session): since the shipped 1 % the
// end-of-line band alone names this drift within its window (1271 of 1630 ms).
TEST(ClosedLoopIssue14, ADriftTheLoopFollowsInAHardStopIsNamedWithinItsWindow) {
  expect_named_in_window_only_with_the_rule("config/scenarios/faults/load_cell_drift_the_loop_follows_in_a_hard_stop.yaml",
                                            "the 0.3 rev hold span once the friction is known",
                                            [](MonitorParams& m) { m.hold_span_known_rev = m.hold_span_rev; },
                                            [](MonitorParams& m) { m.eol_relative = 0.03; });
}

// A load-cell drift while the brake modulates (ABS-like) on a calibrated corner: the thresholds
// learnt from the corner's own residual followed it (1.9 -> 8.7 kN in 3.4 s) and it was never
// named while the loop drove the healthy actuator back past its stroke (tuning seed 1408 run 145).
// Capped at the end-of-line band the fit replaced, the thresholds let it be named within 2 s;
// uncapped, only once the loop has driven the pads below the trusted range (7.66 s, by the
// curve's upper bound there; never before that bound).
TEST(ClosedLoopIssue14, ADriftWhileTheBrakeModulatesCannotWidenTheThresholdsBeyondTheEndOfLineBand) {
  const auto fs = load("config/scenarios/faults/load_cell_drift_while_the_brake_modulates.yaml");
  const double at_s = fs.faults.faults.at(0).at_s;
  const auto named_s = [](const LoopResult& r) {
    const auto& d = r.diagnoses[2 * 5 + static_cast<std::size_t>(Part::LoadCell)];  // RL
    return d.present && d.finding == Finding::LoadCellOffset ? d.detected_s : std::numeric_limits<double>::infinity();
  };
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_LT(named_s(r), at_s + 2.0);
  EXPECT_EQ(r.faults_raised(), 1u);
  auto opts = default_options();
  opts.monitor.calibrated_capped_by_eol = false;
  // Uncapped, the revisit rule (twenty-first session) names it where the modulation has been
  // before (3.3 s after it began); without that rule too:
  const auto revisit = run_closed_loop(fs, opts);
  opts.monitor.revisit = false;
  const auto base = run_closed_loop(fs, opts);
  EXPECT_GT(named_s(base), at_s + 4.0);
  EXPECT_LT(named_s(revisit), named_s(base));
  std::printf("capped: named %.3f s after the drift began; uncapped: %.3f s, without the revisit rule too %.3f s (window %.3f s)\n",
              named_s(r) - at_s, named_s(revisit) - at_s, named_s(base) - at_s, detection_window_s(fs.faults.faults[0]));
}

// A load-cell drift in a hard stop, then a resolver offset on the same corner 0.24 s later
// (tuning seed 1401 run 217). The resolver offset is named at once; without the position the
// residual rules had nothing to judge the load cell against, and the drift was never named in its
// window. Less the offset the confirmed jump measured (resolver_jump.compensate), the resolver
// still gives the position, the end-of-line friction model goes on from where it was before the
// jump, and the drift is named within its window; nothing else is raised.
TEST(ClosedLoopIssue14, ADriftAfterAResolverOffsetOnTheSameCornerIsNamedAgainstTheCompensatedPosition) {
  const auto fs = load("config/scenarios/faults/load_cell_drift_then_a_resolver_offset.yaml");
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 2u);
  // Each named rightly in its window (`correct` asks more: nothing else on the corner in the
  // window, and here each fault's finding is the other's "something else").
  for (const auto& o : r.outcomes) EXPECT_TRUE(o.detected) << to_string(o.diagnosis);
  EXPECT_EQ(r.faults_raised(), 2u);  // the two findings, nothing more
  auto opts = default_options();
  opts.monitor.jump_compensate = false;
  const auto base = run_closed_loop(fs, opts);
  ASSERT_EQ(base.outcomes.size(), 2u);
  EXPECT_FALSE(base.outcomes[0].detected);  // the drift
  EXPECT_TRUE(base.outcomes[1].detected);   // the resolver offset
  std::printf("drift with the compensated position: named after %.0f ms; without: %s after %.0f ms (window %.0f ms)\n",
              r.outcomes[0].latency_ms, to_string(base.outcomes[0].diagnosis), base.outcomes[0].diagnosis_latency_ms,
              1e3 * detection_window_s(fs.faults.faults[0]));
}

// A load-cell drift the loop follows by releasing, in a slow first apply: the pads stay below the
// residual rules' trusted range (1 rev) and no two-sided rule looks there (tuning seed 1408 run
// 364: never named). The end-of-line curve bounds the force from above (residual.low_upper_bound):
// named within the drift's window; without the bound, not within it.
TEST(ClosedLoopIssue14, ADriftBelowTheTrustedRangeIsNamedByTheCurvesUpperBound) {
  expect_named_in_window_only_with_the_rule("config/scenarios/faults/load_cell_drift_below_the_trusted_range.yaml",
                                            "the curve's upper bound below the trusted range",
                                            [](MonitorParams& m) { m.residual_low_upper_bound = false; });
}

// Two faults on one corner: each named rightly in its window (fault `k` of the file only with the
// rule), nothing else raised.
void expect_both_named_fault_k_only_with_the_rule(const std::string& file, std::size_t k, const char* rule,
                                                  const std::function<void(MonitorParams&)>& without) {
  const auto fs = load(file);
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 2u);
  for (const auto& o : r.outcomes) EXPECT_TRUE(o.detected) << to_string(o.fault.type) << " " << to_string(o.diagnosis);
  EXPECT_EQ(r.faults_raised(), 2u);
  auto opts = default_options();
  without(opts.monitor);
  const auto base = run_closed_loop(fs, opts);
  ASSERT_EQ(base.outcomes.size(), 2u);
  EXPECT_FALSE(base.outcomes[k].detected);
  EXPECT_TRUE(base.outcomes[1 - k].detected);
  std::printf("%s with %s: named after %.0f ms; without: %s after %.0f ms (window %.0f ms)\n", to_string(r.outcomes[k].fault.type),
              rule, r.outcomes[k].latency_ms, to_string(base.outcomes[k].diagnosis), base.outcomes[k].diagnosis_latency_ms,
              1e3 * detection_window_s(fs.faults.faults[k]));
}

// A load-cell drift, then the actuator lost and released: the pads below the trusted range, the
// load cell below 0 by more than the keys can pull it (stress seed 1406 run 161).
TEST(ClosedLoopIssue14, ADriftBelowZeroOnAReleasedCaliperIsNamedByTheLowerBound) {
  expect_both_named_fault_k_only_with_the_rule("config/scenarios/faults/load_cell_drift_then_a_total_loss_released.yaml", 0,
                                               "the lower bound below the trusted range",
                                            [](MonitorParams& m) { m.residual_low_lower_bound = false; });
}

// A load-cell drift on a drive seized at the pads' contact, below the trusted range: nothing
// moves, so the load cell's level may not change (tuning seed 1401 run 57).
TEST(ClosedLoopIssue14, ADriftOnACaliperSeizedBelowTheTrustedRangeIsNamedByTheStillDriveRule) {
  expect_both_named_fault_k_only_with_the_rule("config/scenarios/faults/load_cell_drift_on_a_seized_caliper_at_the_pads.yaml", 0,
                                               "the still-drive rule below the trusted range",
                                            [](MonitorParams& m) { m.residual_low_static_span_rev = 0.0; });
}

// A resolver stuck in a held hard stop, then a load-cell drift on the same corner 45 ms later
// (tuning seed 1401 run 394): without the position no residual rule judges the load cell, and the
// drift was never named. The motor has no current then and the drive holds the load, so the
// clamp force cannot rise: the held level is the reference (unpowered.*).
TEST(ClosedLoopIssue14, ADriftAfterAStuckResolverIsNamedAgainstTheUnpoweredHold) {
  expect_both_named_fault_k_only_with_the_rule(
      "config/scenarios/faults/load_cell_drift_after_a_stuck_resolver_in_a_hard_stop.yaml", 1,
      "the unpowered hold", [](MonitorParams& m) { m.unpowered_hold = false; });
}

namespace {

// A fault-free scenario of a caliper effect raises nothing with its end-of-line model and at least
// one finding without it (`without`); the same scenario with a -1 kN bias is still named right.
// A fault-free scenario run with the shipped monitor (every finding it raises a failure, named
// with `what`) and without a rule (`without`): the two runs.
std::pair<LoopResult, LoopResult> fault_free_with_and_without(const char* scenario, const std::string& what,
                                                              const std::function<void(MonitorParams&)>& without) {
  const auto fs = load(scenario);
  EXPECT_TRUE(fs.faults.empty()) << scenario;
  auto r = run_closed_loop(fs, default_options());
  for (const auto& d : r.diagnoses) {
    if (d.present) ADD_FAILURE() << "with " << what << ": " << to_string(d.finding) << " at " << d.detected_s;
  }
  auto opts = default_options();
  without(opts.monitor);
  return {std::move(r), run_closed_loop(fs, opts)};
}

void expect_effect_model_holds(const char* fault_free, const char* biased, const char* model,
                               const std::function<void(MonitorParams&)>& without) {
  const auto [r, base] = fault_free_with_and_without(fault_free, std::string("the ") + model, without);
  EXPECT_GE(base.faults_raised(), 1u);
  const auto b = run_closed_loop(load(biased), default_options());
  ASSERT_EQ(b.outcomes.size(), 1u);
  EXPECT_TRUE(b.outcomes[0].detected) << to_string(b.outcomes[0].diagnosis);
  EXPECT_TRUE(b.outcomes[0].correct);
  std::printf("%s, fault-free: %zu findings with it, %zu without; a -1 kN bias named after %.0f ms\n", model,
              r.faults_raised(), base.faults_raised(), b.outcomes[0].latency_ms);
}

}  // namespace

// Pads that creep (the plant's creep effect: 5 % of a fast step relaxes away with a 1 s time
// constant) on every corner of a healthy car in two hard stops: the holds' relaxation moved the
// load cell against the end-of-line curve, and the hold and level rules named load_cell_offset on
// all four corners (a tuning draw, tune_c run 2, with creep in place of its effects). With the
// caliper's creep as its end-of-line test measured it (residual.end_of_line.creep_model) nothing
// is raised; a -1 kN bias in the second stop is still named in its window.
TEST(ClosedLoopIssue14, PadsThatCreepRaiseNothingAndABiasOnThemIsStillNamed) {
  expect_effect_model_holds("config/scenarios/faults/fault_free_pad_creep_hard_stops.yaml",
                            "config/scenarios/faults/load_cell_bias_in_a_hard_stop_with_pad_creep.yaml", "creep model",
                            [](MonitorParams& m) { m.eol_creep_model = false; });
}

// Keys whose friction grows with the clamp force (the plant's load-dependent friction, twice as
// wide at 40 kN) on the same drive: the end-of-line friction model and its bands, measured as one
// width, were half as wide as the keys' in the hard stops. Scaled with the force
// (residual.end_of_line.friction_load_model) nothing is raised, and a -1 kN bias is still named.
TEST(ClosedLoopIssue14, KeysWhoseFrictionGrowsWithTheForceRaiseNothingAndABiasIsStillNamed) {
  expect_effect_model_holds("config/scenarios/faults/fault_free_load_dependent_friction_hard_stops.yaml",
                            "config/scenarios/faults/load_cell_bias_in_a_hard_stop_with_load_dependent_friction.yaml",
                            "load-dependent friction model", [](MonitorParams& m) { m.eol_friction_load_model = false; });
}

// A load cell whose offset moves with temperature (the plant's thermal drift, 0.9-1.0 kN at
// 86-90 C) on every corner: released, the readings sat an offset above the end-of-line curve.
// Expecting the offset the end-of-line test measured (residual.end_of_line.thermal_offset_model)
// nothing is raised, and a -1 kN bias is still named.
TEST(ClosedLoopIssue14, ALoadCellThatDriftsWithTemperatureRaisesNothingAndABiasIsStillNamed) {
  expect_effect_model_holds("config/scenarios/faults/fault_free_thermal_drift_hot_hard_stops.yaml",
                            "config/scenarios/faults/load_cell_bias_in_a_hard_stop_with_thermal_drift.yaml",
                            "thermal offset model", [](MonitorParams& m) { m.eol_thermal_offset_model = false; });
}

// A calibrated caliper with viscous friction (0.2 kN per rev/s) reversing from a -2 rev/s release
// into a +2.7 rev/s apply (extreme hunt seed 2613, run 18): the change rule's reference was set
// near standstill and the viscous term moved the residual by 0.55 kN against its 0.48 kN. With the
// viscous friction as the end-of-line test measured it in the expected reading
// (residual.end_of_line.viscous_model) nothing is raised, and a -1 kN bias just after the
// reversal is still named.
TEST(ClosedLoopIssue14, AViscousCaliperReversingFastRaisesNothingAndABiasIsStillNamed) {
  expect_effect_model_holds("config/scenarios/faults/fault_free_viscous_caliper_fast_reversal.yaml",
                            "config/scenarios/faults/load_cell_bias_in_a_fast_reversal_of_a_viscous_caliper.yaml",
                            "viscous model", [](MonitorParams& m) {
                              m.eol_viscous_model = false;
                              // (Its calibrator started from the configured curve, as when the
                              // rule was made: from the caliper's own, the residual stays within it.)
                              m.calibrator_initial_curve_from_eol = false;
                            });
}

// A +1.08 kN/s drift before the first fit on that kind of caliper (tuning seed 1401, run 22): the
// apply at 4 rev/s no longer adds its viscous term to the residual, so the speed allowance no longer
// holds it either (residual.end_of_line.viscous_narrows_speed_allowance): named in its window.
// With the allowance still holding it, named past the window.
TEST(ClosedLoopIssue14, ADriftOnAViscousCaliperIsNamedOnceTheAllowanceNoLongerHoldsTheModelledTerm) {
  const auto fs = load("config/scenarios/faults/load_cell_drift_in_a_fast_apply_of_a_viscous_caliper.yaml");
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected) << to_string(r.outcomes[0].diagnosis);
  EXPECT_TRUE(r.outcomes[0].correct);
  auto opts = default_options();
  opts.monitor.eol_viscous_narrows_speed_allowance = false;
  const auto wide = run_closed_loop(fs, opts);
  ASSERT_EQ(wide.outcomes.size(), 1u);
  EXPECT_FALSE(wide.outcomes[0].detected) << "named in its window with the allowance holding the modelled term too";
  std::printf("a drift on a viscous caliper: named after %.0f ms; with the wide allowance %s\n", r.outcomes[0].latency_ms,
              wide.outcomes[0].detected ? "also" : "not in its window");
}

// A fault-free scenario that raised `finding` on one corner without a rule (`without`) and raises
// nothing with it.
void expect_quiet_only_with_the_rule(const char* scenario, const char* rule, Finding finding,
                                     const std::function<void(MonitorParams&)>& without) {
  const auto [r, base] = fault_free_with_and_without(scenario, rule, without);
  std::size_t named = 0;
  for (const auto& d : base.diagnoses) {
    if (d.present && d.finding == finding) ++named;
  }
  EXPECT_GE(named, 1u) << "without " << rule;
  std::printf("%s: %zu findings with it, %zu without (%zu %s)\n", rule, r.faults_raised(), base.faults_raised(), named,
              to_string(finding));
}

// A released caliper whose keys hold 3.6 kN of friction and whose hot load cell reads 0.65 kN of
// offset (the extreme population with the plant's newer effects, hunt run 193): at rest against a
// zero command the not-releasing rule took the 4.2 kN reading for a brake holding force. Bounded by
// the clamp force the end-of-line curve allows at the position (0 there) it raises nothing; a drive
// seized in a hot hard stop is still named in its window.
TEST(ClosedLoopIssue14, KeysHoldingFrictionAtTheReleasedPositionAreNotABrakeThatDoesNotRelease) {
  expect_quiet_only_with_the_rule("config/scenarios/faults/fault_free_released_keys_holding_friction_hot.yaml",
                                  "the not-releasing rule bounded by the position", Finding::ActuatorNotReleasing,
                                  [](MonitorParams& m) { m.tracking_excess_position_bound = false; });
  const auto seized = run_closed_loop(load("config/scenarios/faults/actuator_seized_in_hard_stop_hot.yaml"), default_options());
  ASSERT_EQ(seized.outcomes.size(), 1u);
  EXPECT_TRUE(seized.outcomes[0].detected) << to_string(seized.outcomes[0].diagnosis);
}

// A hold settled in a slow release, the drive down below the trusted range and slowly back up
// (extreme hunt run 44): the keys' friction reversed by 2.1 kN meanwhile. The hold restarts where
// the residual is not judged (hold.restart_untrusted); kept, it named load_cell_offset at 4.2 s.
TEST(ClosedLoopIssue14, AHoldRestartsAfterTheDriveLeftTheTrustedRange) {
  expect_quiet_only_with_the_rule("config/scenarios/faults/fault_free_slow_reversal_below_the_trusted_range.yaml",
                                  "the hold restarted below the trusted range", Finding::LoadCellOffset,
                                  [](MonitorParams& m) {
                                    m.hold_restart_untrusted = false;
                                    start_as_configured(m);
                                  });
}

// A caliper ten times softer than the shipped one travels beyond 10 rev in hard stops (soft10_ff
// run 126). With the guard's shipped 10 rev, its samples up there are rejected and its drive turns
// round unseen; back below, a gap of unseen positions forgets the end-of-line friction model's and
// the calibrator's friction states (residual.unseen_gap_forgets); kept, their way-up state named
// load_cell_offset at 13.87 s.
TEST(ClosedLoopIssue14, AGapOfUnseenPositionsForgetsTheKeysState) {
  const auto fs = load("config/scenarios/faults/fault_free_soft_caliper_back_from_beyond_the_guard.yaml");
  auto opts = default_options();
  opts.monitor.guard_position_from_eol = false;  // the gap: samples beyond 10 rev rejected
  const auto r = run_closed_loop(fs, opts);
  const std::size_t fl = 0;
  EXPECT_GT(r.guard_rejected[fl], 100u);
  EXPECT_EQ(r.faults_raised(), 0u);
  opts.monitor.residual_unseen_gap_forgets = false;
  const auto base = run_closed_loop(fs, opts);
  EXPECT_EQ(load_cell(base, fl).finding, Finding::LoadCellOffset) << to_string(load_cell(base, fl).finding);
  std::printf("FL beyond the guard (%llu samples rejected): %zu findings forgetting, %zu keeping (%s)\n",
              static_cast<unsigned long long>(r.guard_rejected[fl]), r.faults_raised(), base.faults_raised(),
              to_string(load_cell(base, fl).finding));
}

// The same caliper's guard takes positions up to where its end-of-line curve reaches the load
// cell's range (guard.position_from_end_of_line): none of its samples is corrupt, and nothing is
// raised. With the shipped 10 rev alone, hundreds of healthy samples are counted corrupt.
TEST(ClosedLoopIssue14, ASoftCalipersTravelBeyondTenRevIsNotCorrupt) {
  const auto fs = load("config/scenarios/faults/fault_free_soft_caliper_back_from_beyond_the_guard.yaml");
  const auto r = run_closed_loop(fs, default_options());
  const std::size_t fl = 0;
  EXPECT_EQ(r.guard_rejected[fl], 0u);
  EXPECT_EQ(r.faults_raised(), 0u);
  auto opts = default_options();
  opts.monitor.guard_position_from_eol = false;
  const auto base = run_closed_loop(fs, opts);
  EXPECT_GT(base.guard_rejected[fl], 100u);
  std::printf("FL's samples rejected: %llu with the end-of-line range, %llu with 10 rev\n",
              static_cast<unsigned long long>(r.guard_rejected[fl]), static_cast<unsigned long long>(base.guard_rejected[fl]));
}

namespace {

// The worst |estimate - clamp force| of a corner from `from_s` on (its load cell lost), with the
// monitor changed by `change`, and whether the run raised that corner's load-cell finding only
// (besides the scenario's other faults, named in `others`).
struct LostLoadCellRun {
  double worst_kN = 0.0, worst_at_s = 0.0;
  bool only_its_faults = false;
  std::uint64_t guard_rejected = 0;  // the corner's samples the guard rejected
};
LostLoadCellRun lost_load_cell_run(const FaultScenario& fs, std::size_t corner, double from_s, std::size_t others,
                                   const std::function<void(MonitorParams&)>& change) {
  auto opts = default_options();
  change(opts.monitor);
  const auto r = run_closed_loop(fs, opts);
  LostLoadCellRun seen;
  for (const auto& p : r.periods) {
    if (p.time_s < from_s || !std::isfinite(p.true_kN[corner]) || !std::isfinite(p.estimate_kN[corner])) continue;
    const double e = std::abs(p.estimate_kN[corner] - p.true_kN[corner]);
    if (e > seen.worst_kN) seen = LostLoadCellRun{e, p.time_s, false};
  }
  seen.only_its_faults =
      r.faults_raised() == 1 + others && r.diagnoses[corner * 5 + static_cast<std::size_t>(Part::LoadCell)].active;
  seen.guard_rejected = r.guard_rejected[corner];
  return seen;
}

}  // namespace

// A soft caliper's load cell lost in a hard stop beyond the calibrator's range (faster-driver
// campaign `fast`, run 68: the extreme population's member 14, 0.4 x as stiff as the shipped
// caliper; RL's dropout at 7.467 s in a 14.7 kN hold at 7.7 rev; its fits had data over 3.8-6 rev).
// Its calibrator started from the shipped caliper's curve, which its fits replaced only over
// 3.8-6 rev: released at 1.4-2.4 rev the curve it was left with read 5-8 kN where it clamped 1,
// and the CCU named an actuator that released as not releasing. Now it starts from the caliper's
// own end-of-line curve (calibrator_start.initial_curve_from_end_of_line).
TEST(ClosedLoopIssue14, ASoftCalipersLostLoadCellLeavesACurveThatFollowsItsClampForce) {
  const auto fs = load("config/scenarios/faults/soft_caliper_load_cell_lost_in_a_hard_stop.yaml");
  const std::size_t rl = 2;
  const auto both = lost_load_cell_run(fs, rl, 7.5, 0, [](MonitorParams&) {});
  const auto no_start = lost_load_cell_run(fs, rl, 7.5, 0, [](MonitorParams& m) { m.calibrator_initial_curve_from_eol = false; });
  const auto neither = lost_load_cell_run(fs, rl, 7.5, 0, [](MonitorParams& m) {
    m.calibrator_initial_curve_from_eol = false;
    m.lost_load_cell_curve_from_eol = false;
  });
  std::printf("RL's estimate after its load cell was lost, worst |estimate - clamp force|: %.2f kN (at %.2f s) with the "
              "end-of-line start, %.2f (%.2f s) without it, %.2f (%.2f s) without it and the bridge\n",
              both.worst_kN, both.worst_at_s, no_start.worst_kN, no_start.worst_at_s, neither.worst_kN, neither.worst_at_s);
  EXPECT_LT(both.worst_kN, 1.0);
  EXPECT_TRUE(both.only_its_faults);
  EXPECT_GT(no_start.worst_kN, 2.5);
  EXPECT_GT(neither.worst_kN, 5.0);
  EXPECT_FALSE(neither.only_its_faults);
}

// A load cell stuck before the first fit in a hard stop at 9.4 rev, on a caliper ten times softer
// (soft10 campaign, seed 2906, run 72, FL; without that run's link delay on RR). Beyond the calibrator's
// 1-6 rev its starting cubic, extrapolated, was 11 kN off. Now the caliper's end-of-line curve
// carries the curve beyond where the fits had data (load_cell_lost.curve_from_end_of_line_beyond_data).
TEST(ClosedLoopIssue14, BeyondTheFitsDataTheEndOfLineCurveCarriesALostLoadCellsCurve) {
  const auto fs = load("config/scenarios/faults/soft_caliper_load_cell_stuck_beyond_the_calibrators_range.yaml");
  const std::size_t fl = 0;
  const auto with = lost_load_cell_run(fs, fl, 0.87, 0, [](MonitorParams&) {});
  const auto without = lost_load_cell_run(fs, fl, 0.87, 0, [](MonitorParams& m) { m.lost_load_cell_curve_from_eol = false; });
  std::printf("FL's estimate after its load cell stuck, worst |estimate - clamp force|: %.2f kN (at %.2f s) with the "
              "bridge, %.2f (%.2f s) without\n", with.worst_kN, with.worst_at_s, without.worst_kN, without.worst_at_s);
  EXPECT_LT(with.worst_kN, 1.0);
  EXPECT_TRUE(with.only_its_faults);
  EXPECT_GT(without.worst_kN, 5.0);
}

// A load-cell drift named in a hard stop keeps drifting (tuning seed 1401, run 62: -1.656 kN/s on
// FR). At 16.6 s its value passes the guard's -10 kN. The CCU no longer uses it, yet every sample
// was rejected as corrupt for it: FR unseen while its brake released, its estimate frozen at 16.6
// kN. Now the diagnosed load cell's value out of range is no value (guard.diagnosed_load_cell_out_of_range_is_absent).
TEST(ClosedLoopIssue14, ADiagnosedLoadCellDriftingOutOfRangeDoesNotBlindTheCcu) {
  const auto fs = load("config/scenarios/faults/load_cell_drift_past_the_guards_range.yaml");
  const std::size_t fr = 1;
  const auto with = lost_load_cell_run(fs, fr, 1.5, 0, [](MonitorParams&) {});
  const auto without = lost_load_cell_run(fs, fr, 1.5, 0, [](MonitorParams& m) { m.guard_diagnosed_load_cell_absent = false; });
  std::printf("FR's estimate after its drift was named, worst |estimate - clamp force|: %.2f kN (at %.2f s) with the rule, "
              "%.2f (%.2f s) without; samples rejected %llu and %llu\n",
              with.worst_kN, with.worst_at_s, without.worst_kN, without.worst_at_s,
              static_cast<unsigned long long>(with.guard_rejected), static_cast<unsigned long long>(without.guard_rejected));
  EXPECT_LT(with.worst_kN, 1.0);
  EXPECT_TRUE(with.only_its_faults);
  EXPECT_EQ(with.guard_rejected, 0u);
  EXPECT_GT(without.worst_kN, 10.0);
  EXPECT_GT(without.guard_rejected, 100u);
}

namespace {

// The worst |estimate - clamp force| of a corner over [from_s, to_s].
double worst_estimate_error_kN(const LoopResult& r, std::size_t corner, double from_s, double to_s) {
  double worst = 0.0;
  for (const auto& p : r.periods) {
    if (p.time_s < from_s || p.time_s > to_s || !std::isfinite(p.true_kN[corner]) || !std::isfinite(p.estimate_kN[corner])) continue;
    worst = std::max(worst, std::abs(p.estimate_kN[corner] - p.true_kN[corner]));
  }
  return worst;
}

}  // namespace

// A corner back from a lost link (faster-driver campaign run 27: a 0.76 s silence) or from a
// resolver named stuck (run 377) restarts its calibrator from the last good curve and friction
// stiffnesses. In the slow release that follows, keys 3.7 kN wide hold the clamp force 3-3.3 kN
// above the command, as they should. The tracking rules counted the calibrator's friction only
// after a fit of the restarted calibrator's own: until then the keys' friction was a brake holding
// force, and the healthy actuator was named actuator_not_releasing. Now the restarted calibrator's
// friction counts once its states are known again (tracking.friction_after_restart).
TEST(ClosedLoopIssue14, ARestartedCalibratorsFrictionCountsOnceItsStatesAreKnownAgain) {
  struct Case {
    const char* scenario;
    std::size_t corner;
  };
  for (const Case c : {Case{"config/scenarios/faults/viscous_keys_slow_release_after_a_link_silence.yaml", 3},
                       Case{"config/scenarios/faults/keys_slow_release_after_a_stuck_resolver_cleared.yaml", 2}}) {
    const auto fs = load(c.scenario);
    const auto r = run_closed_loop(fs, default_options());
    ASSERT_EQ(r.outcomes.size(), 1u) << c.scenario;
    EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct) << c.scenario << ": " << to_string(r.outcomes[0].diagnosis);
    EXPECT_EQ(r.faults_raised(), 1u) << c.scenario;
    EXPECT_FALSE(actuator(r, c.corner).present) << c.scenario << ": " << to_string(actuator(r, c.corner).finding);
    auto opts = default_options();
    opts.monitor.tracking_friction_after_restart = false;
    start_as_configured(opts.monitor);
    const auto base = run_closed_loop(fs, opts);
    EXPECT_EQ(actuator(base, c.corner).finding, Finding::ActuatorNotReleasing)
        << c.scenario << ": without the rule " << to_string(actuator(base, c.corner).finding);
    std::printf("%s: %zu findings with the restarted calibrator's friction, %zu without (%s at %.3f s)\n", c.scenario,
                r.faults_raised(), base.faults_raised(), to_string(actuator(base, c.corner).finding),
                actuator(base, c.corner).detected_s);
  }
}

// A resolver offset on RL in a 10 kN hold, keys 3.7 kN wide (faster-driver campaign run 55). The
// jump swung the calibrator's friction states from +3.8 to -4.9 kN before the offset was named;
// the estimate after the finding is the load cell less the friction frozen then. Frozen at the
// confirming sample it stood 6.4 kN above the clamp force, and the healthy actuator was named
// actuator_not_releasing; frozen from before the onset (resolver_lost.friction_from_before_onset)
// it is right, and the tracking rules count that friction as they count the calibrator's
// (resolver_lost.tracking_counts_friction): without that, the keys holding the clamp force 2.7 kN
// below the 10 kN command were named actuator_tracking.
TEST(ClosedLoopIssue14, AResolverFindingFreezesTheFrictionFromBeforeItsOnset) {
  const auto fs = load("config/scenarios/faults/resolver_offset_in_a_hold_of_wide_keys.yaml");
  const std::size_t rl = 2;
  const double named_s = 4.39, back_s = 6.1;  // the offset named; the resolver right again at 6.148 s
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct) << to_string(r.outcomes[0].diagnosis);
  EXPECT_EQ(r.faults_raised(), 1u);
  const double with_kN = worst_estimate_error_kN(r, rl, named_s, back_s);
  EXPECT_LT(with_kN, 1.5);
  // Frozen at the finding: the estimate is off by the jump's swing (the tracking rules, counting
  // the same wrong friction, judge the load cell and name nothing).
  auto opts = default_options();
  opts.monitor.lost_resolver_friction_before_onset = false;
  const auto at_finding = run_closed_loop(fs, opts);
  const double at_finding_kN = worst_estimate_error_kN(at_finding, rl, named_s, back_s);
  EXPECT_GT(at_finding_kN, 5.0);
  // ... and without either rule (the campaign's run), the healthy actuator is named.
  opts.monitor.lost_resolver_tracking_counts_friction = false;
  const auto neither = run_closed_loop(fs, opts);
  EXPECT_EQ(actuator(neither, rl).finding, Finding::ActuatorNotReleasing) << to_string(actuator(neither, rl).finding);
  // The friction from before the onset, uncounted: the keys' part of the shortfall is the actuator's.
  opts = default_options();
  opts.monitor.lost_resolver_tracking_counts_friction = false;
  start_as_configured(opts.monitor);  // (started from the keys, the shortfall stays within the band)
  const auto uncounted = run_closed_loop(fs, opts);
  EXPECT_EQ(actuator(uncounted, rl).finding, Finding::ActuatorTracking) << to_string(actuator(uncounted, rl).finding);
  std::printf("RL after its resolver offset was named: worst |estimate - clamp force| %.2f kN with the friction from "
              "before the onset, %.2f kN frozen at the finding; without either rule %s, the friction uncounted %s\n",
              with_kN, at_finding_kN, to_string(actuator(neither, rl).finding), to_string(actuator(uncounted, rl).finding));
}

// A caliper with the plant's viscous friction, driven 2.5 times faster (faster-driver campaign
// run 267): its applies at up to 25 rev/s add 2-5 kN of viscous force to the load cell, which the
// calibrator's fits took for key friction (8.7 kN on keys that hold 3.2): in the 34.5 kN hard stop
// the estimate was 5.5 kN low, before and after its drive seized. The end-of-line test measured
// the viscous friction, and the corner's calibrator now fits its own viscous term
// (calibrator_start.viscous_term_from_end_of_line). The seizure is still named in its window.
TEST(ClosedLoopIssue14, AViscousCalipersCalibratorFitsItsOwnViscousTerm) {
  const auto fs = load("config/scenarios/faults/viscous_caliper_seized_in_a_hard_stop_of_a_fast_driver.yaml");
  const std::size_t fl = 0;
  // From its first fit (6.3 s) to the seized drive's release: holds, fast applies and releases,
  // the hard stop and the seizure in it. (Before the first fit the estimate is the load cell less
  // the end-of-line keys with the rule, the load cell as it is without: not compared.)
  const double from_s = 6.5, to_s = 15.7;
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct) << to_string(r.outcomes[0].diagnosis);
  EXPECT_EQ(r.faults_raised(), 1u);
  auto opts = default_options();
  opts.monitor.calibrator_viscous_from_eol = false;
  start_as_configured(opts.monitor);  // (from the end-of-line keys as its prior: 3.9 kN off in the hard stop)
  const auto base = run_closed_loop(fs, opts);
  const double with_kN = worst_estimate_error_kN(r, fl, from_s, to_s);
  const double without_kN = worst_estimate_error_kN(base, fl, from_s, to_s);
  const double hold_without_kN = worst_estimate_error_kN(base, fl, 14.0, to_s);
  std::printf("FL from its first fit to the seizure's end, worst |estimate - clamp force|: %.2f kN with its own viscous "
              "term, %.2f without (%.2f in the hard stop)\n", with_kN, without_kN, hold_without_kN);
  EXPECT_LT(with_kN, 0.5);
  EXPECT_GT(hold_without_kN, 4.0);
}

// Calipers three to ten times stiffer with backlash, their force loops hunting in the play: the
// motor goes 0.06 rev down and back up while the clamp force stands (stiff10 run 339, fault-free).
// Before the play's state is known, the hold's allowance for it counted the curve's net change
// (0.2 kN) and not the 1.1 kN of the motor's crossing: load_cell_offset on RR and RL. Counted over
// the span of the motor's positions (residual.hold.play_allowance_over_span), nothing is raised.
TEST(ClosedLoopIssue14, AForceLoopHuntingAcrossThePlayIsNotALoadCellOffset) {
  expect_quiet_only_with_the_rule("config/scenarios/faults/fault_free_stiff_calipers_hunting_in_their_play.yaml",
                                  "the hold's play allowance over the motor's span", Finding::LoadCellOffset,
                                  [](MonitorParams& m) { m.hold_play_allowance_over_span = false; });
}

// Beside a resolver offset on FL, RR (ten times stiffer, backlash, keys 3.4 kN wide) moved its motor
// 0.053 rev back across the play in a hold, the clamp force standing (stiff10 run 13). Before the
// play's state is known the end-of-line residual reads the curve at the motor's position: it moved
// 1.4 kN past the band, and RR was named load_cell_offset. With the band's play allowance
// (residual.end_of_line.play_allowance) only FL's offset is named, in its window.
TEST(ClosedLoopIssue14, TheEndOfLineBandAllowsForThePlayWhileItsStateIsUnknown) {
  const auto fs = load("config/scenarios/faults/resolver_offset_beside_a_stiff_caliper_crossing_its_play.yaml");
  const std::size_t rr = 3;
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct) << to_string(r.outcomes[0].diagnosis);
  EXPECT_EQ(r.faults_raised(), 1u);
  auto opts = default_options();
  opts.monitor.eol_play_allowance = false;
  const auto base = run_closed_loop(fs, opts);
  EXPECT_EQ(load_cell(base, rr).finding, Finding::LoadCellOffset) << to_string(load_cell(base, rr).finding);
  std::printf("RR beside FL's resolver offset: %zu findings with the play allowance, %zu without (RR %s at %.3f s)\n",
              r.faults_raised(), base.faults_raised(), to_string(load_cell(base, rr).finding), load_cell(base, rr).detected_s);
}

// Load cells lagging their resolvers by 5 ms (the plant's sensor delay) in ABS-like modulation, on a
// caliper up to ten times softer with 4 kN keys (soft10 run 29) and on one up to ten times stiffer
// (stiff10_ff run 3), fault-free. At each reversal the end-of-line friction model flipped 5 ms
// before the load cell: steps of the residual named FL's load cell noisy, and RR's offset. With the
// model on the position the reading belongs to, as the end-of-line test measured the lag
// (residual.end_of_line.delay_model), nothing is raised.
TEST(ClosedLoopIssue14, TheEndOfLineModelFollowsALaggingLoadCell) {
  expect_quiet_only_with_the_rule("config/scenarios/faults/fault_free_soft_caliper_lagging_load_cell_in_abs.yaml",
                                  "the end-of-line model on the lagged position", Finding::LoadCellNoisy,
                                  [](MonitorParams& m) {
                                    m.eol_delay_model = false;
                                    start_as_configured(m);
                                  });
  expect_quiet_only_with_the_rule("config/scenarios/faults/fault_free_stiff_caliper_lagging_load_cell_in_abs.yaml",
                                  "the end-of-line model on the lagged position", Finding::LoadCellOffset,
                                  [](MonitorParams& m) {
                                    m.eol_delay_model = false;
                                    start_as_configured(m);
                                  });
}

// A hold's reference is set only from settle samples that lie within hold.settled_within_kN of
// each other (soft10_ff run 2): FL's 5 ms load-cell lag after its wide keys reversed made the
// residual fall 1.3 kN across the settle samples; their mean, taken as the hold's level, named
// load_cell_offset at 2.305 s once the residual came to rest 0.85 kN below it. (Since the
// end-of-line model follows the lagged position, residual.end_of_line.delay_model, the lag no longer
// moves the residual there: the rule is tested without that model, on the residual it was made for.)
TEST(ClosedLoopIssue14, AHoldSettlesOnlyWhereTheResidualHasStoppedMoving) {
  expect_quiet_only_with_the_rule("config/scenarios/faults/fault_free_soft_caliper_hold_after_delayed_key_reversal.yaml",
                                  "the hold settled only on a level residual", Finding::LoadCellOffset,
                                  [](MonitorParams& m) {
                                    m.hold_settled_within_kN = 0.0;
                                    m.eol_delay_model = false;
                                  });
}

// On a caliper ten times stiffer with backlash (stiff10_ff run 1), before the play's state is known
// the hold rule reads the curve at the motor's position: the force loop creeping the motor 0.015
// rev inside the play at a constant 5.13 kN moved the residual by -0.77 kN (load_cell_offset at
// 1.796 s). The hold's allowance adds the curve's change over the motor's motion, at most across
// the play (hold.play_allowance).
TEST(ClosedLoopIssue14, AMotorCreepingInsideThePlayIsNotALoadCellDrift) {
  expect_quiet_only_with_the_rule("config/scenarios/faults/fault_free_stiff_caliper_motor_creeping_in_the_play.yaml",
                                  "the hold's play allowance", Finding::LoadCellOffset,
                                  [](MonitorParams& m) { m.hold_play_allowance = false; });
}

// A healthy 0.08 kN load cell that goes below the trusted range after a hard stop's release
// (extreme hunt seed 2613, run 478): its second differences' level, learnt afresh when they took
// over from the residual's steps (noise.paths_restart_learning), is its own; learnt from one
// sample weighed by the residual path's time, it named load_cell_noisy at 2.196 s.
TEST(ClosedLoopIssue14, ANoisyHealthyLoadCellReleasedLearnsItsOwnLevel) {
  expect_quiet_only_with_the_rule("config/scenarios/faults/fault_free_noisy_load_cell_released.yaml",
                                  "the noise paths restarting each other's learning", Finding::LoadCellNoisy,
                                  [](MonitorParams& m) {
                                    m.noise_paths_restart_learning = false;
                                    start_as_configured(m);
                                  });
}

// A drive seized as a hard stop applies (extreme hunt seed 2614, run 262): named, and nothing else.
// The healthy FL, released from the hard stop, rests with its 3.9 kN keys pulling its load cell to
// -3.9 kN against a zero command; the shortfall counts no clamp force below 0 nor below what the
// end-of-line curve allows there (tracking.shortfall_position_bound). Without: actuator_tracking.
TEST(ClosedLoopIssue14, KeysPullingALoadCellBelowZeroAreNotABrakeShortOfItsCommand) {
  const auto fs = load("config/scenarios/faults/actuator_seized_in_a_hard_stop_beside_wide_keys.yaml");
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected) << to_string(r.outcomes[0].diagnosis);
  EXPECT_EQ(r.faults_raised(), 1u);  // FR's
  const std::size_t fl = 0;
  EXPECT_FALSE(actuator(r, fl).present) << to_string(actuator(r, fl).finding);
  auto opts = default_options();
  opts.monitor.tracking_shortfall_position_bound = false;
  start_as_configured(opts.monitor);
  const auto base = run_closed_loop(fs, opts);
  EXPECT_EQ(actuator(base, fl).finding, Finding::ActuatorTracking) << to_string(actuator(base, fl).finding);
  std::printf("seized FR beside wide keys: FL %s with the bound, %s without\n", to_string(actuator(r, fl).finding),
              to_string(actuator(base, fl).finding));
}

// A total loss while a hard stop applies at the speed limit: the motor brakes with -40 A and the
// rotor coasts on (tuning seed 1403 run 158). Named lost by the braking rule in its window; never
// without it.
TEST(ClosedLoopIssue14, ATotalLossWhileApplyingAtSpeedIsNamedByTheBrakingRule) {
  expect_named_in_window_only_with_the_rule("config/scenarios/faults/total_loss_while_applying_at_speed.yaml",
                                            "the lost rule while braking at speed",
                                            [](MonitorParams& m) { m.torque_lost_braking = false; });
}

// A 59 % torque loss while the demand comes down slowly, then a load-cell bias on the same corner
// 0.121 s later (stress seed 1406 run 112): the motor holds the screw back against the load, and
// the weaker motor needs more current for it. The torque-loss rule while braking at speed names
// the loss 58 ms in, before the bias. Without it the loss was named wrongly (the bias took the
// load cell the other rules judge it by: load_cell_offset); since the corner restarts its force
// loop at the switch to curve feedback (controller.feedback_switch_restart), the loop on the
// curve after the bias shows the loss to the other rules, which name it 306 ms in, within its
// 1 s window but five times later.
TEST(ClosedLoopIssue14, ATorqueLossInASlowReleaseIsNamedWhileTheMotorHoldsBack) {
  const auto fs = load("config/scenarios/faults/torque_loss_then_a_load_cell_bias_in_a_slow_release.yaml");
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 2u);
  for (const auto& o : r.outcomes) EXPECT_TRUE(o.detected) << to_string(o.fault.type) << " " << to_string(o.diagnosis);
  EXPECT_EQ(r.faults_raised(), 2u);
  EXPECT_LT(r.outcomes[0].latency_ms, 100.0);
  auto opts = default_options();
  opts.monitor.torque_loss_braking_threshold = 0.0;
  const auto base = run_closed_loop(fs, opts);
  ASSERT_EQ(base.outcomes.size(), 2u);
  EXPECT_TRUE(!base.outcomes[0].detected || base.outcomes[0].latency_ms > 200.0) << base.outcomes[0].latency_ms;
  EXPECT_TRUE(base.outcomes[1].detected);
  std::printf("torque_loss with the torque-loss rule while braking at speed: named after %.0f ms; without: %s after %.0f ms\n",
              r.outcomes[0].latency_ms, to_string(base.outcomes[0].diagnosis), base.outcomes[0].diagnosis_latency_ms);
}

// A total loss 0.1 s after a resolver offset on the same corner (tuning seed 1403 run 780): the
// torque rules go on with the resolver's speed and its position less the offset.
TEST(ClosedLoopIssue14, ATotalLossAfterAResolverOffsetIsNamedByTheTorqueRules) {
  expect_both_named_fault_k_only_with_the_rule("config/scenarios/faults/resolver_offset_then_a_total_loss.yaml", 1,
                                               "the torque rules after a resolver offset",
                                               [](MonitorParams& m) { m.torque_after_resolver_offset = false; });
}

// A drive seized while it holds 35 kN, after a resolver offset (tuning seed 1403 run 360): its
// current winds up past 6.5 A, where the tests' lagging - half no longer crossed 0 on average;
// recognised by each half's extreme sample, the unanswered tests name it lost in its window.
TEST(ClosedLoopIssue14, ADriveSeizedAtAHighHoldCurrentIsNamedByItsUnansweredTests) {
  expect_both_named_fault_k_only_with_the_rule("config/scenarios/faults/resolver_offset_then_a_drive_seized_in_a_hard_stop.yaml", 0,
                                               "the tests recognised by their extreme samples",
                                               [](MonitorParams& m) { m.test_pulse_crossing_extremes = false; });
}

// A total loss during a link silence: the load spins the drive back onto the plant's retracted
// end stop, where its samples are plausible again, and the loss is named in its window (tuning
// seed 1401 run 81). With the stop 5 rev back the drive ran past the monitor's plausible range
// (-1 rev): every later sample was rejected and the loss was never named.
TEST(ClosedLoopIssue14, ATotalLossDuringALinkSilenceIsNamedAgainstTheEndStop) {
  auto fs = load("config/scenarios/faults/total_loss_after_a_link_silence.yaml");
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 2u);
  for (const auto& o : r.outcomes) EXPECT_TRUE(o.detected) << to_string(o.fault.type) << " " << to_string(o.diagnosis);
  EXPECT_EQ(r.faults_raised(), 2u);
  fs.scenario.plant.transmission.retracted_stop_rev = -5.0;
  const auto base = run_closed_loop(fs, default_options());
  ASSERT_EQ(base.outcomes.size(), 2u);
  EXPECT_FALSE(base.outcomes[1].detected);
  std::printf("total loss against the stop: named after %.0f ms; stop 5 rev back: %s\n", r.outcomes[1].latency_ms,
              to_string(base.outcomes[1].diagnosis));
}

// A loop on a noisy load cell released the healthy drive onto the end stop and pulled there
// (stress seed 1406 run 362): the stop takes the pull and the tests' - half, and without the
// monitor's allowance for the stop (torque.stop_margin_rev) the healthy drive was named lost. With
// the eighteenth session's corner (its curve estimate below the trusted range, its home limit)
// the same scenario no longer pulls on the stop, with or without the limit: only the load cell is
// named either way, and this test no longer shows the allowance's effect (docs/faults.md).
TEST(ClosedLoopIssue14, AHealthyDriveReleasedOntoTheEndStopIsNotNamed) {
  auto fs = load("config/scenarios/faults/load_cell_noise_released_onto_the_end_stop.yaml");
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct) << to_string(r.outcomes[0].diagnosis);
  EXPECT_EQ(r.faults_raised(), 1u);
  auto never_at_the_stop = default_options();
  never_at_the_stop.monitor.torque_stop_margin_rev = -1.0;
  EXPECT_EQ(run_closed_loop(fs, never_at_the_stop).faults_raised(), 1u);
  fs.scenario.controller.force_home_limit = false;
  EXPECT_EQ(run_closed_loop(fs, default_options()).faults_raised(), 1u);
  EXPECT_EQ(run_closed_loop(fs, never_at_the_stop).faults_raised(), 1u);
  // The curve estimate below the trusted range: a drive on its curve after a dropout, released
  // onto the stop, is not named (tuning seed 1403 run 30: the cubic read 5.9 kN at the home).
  const auto d = run_closed_loop(load("config/scenarios/faults/load_cell_dropout_released_onto_the_end_stop.yaml"),
                                 default_options());
  ASSERT_EQ(d.outcomes.size(), 2u);
  for (const auto& o : d.outcomes) EXPECT_TRUE(o.detected) << to_string(o.fault.type) << " " << to_string(o.diagnosis);
  EXPECT_EQ(d.faults_raised(), 2u);
}

// The end-of-line friction model follows the position while the load cell gives no value: the
// dropout's finding clears when the load cell is back and nothing else is raised (tuning seed
// 1401 run 244: a false load_cell_offset 20 ms after it cleared, the model left where the
// dropout began while the apply rose, fell and rose again).
TEST(ClosedLoopIssue14, AfterADropoutAcrossAReversalTheFrictionModelStillKnowsItsState) {
  const auto fs = load("config/scenarios/faults/load_cell_dropout_across_a_reversal.yaml");
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct);
  EXPECT_EQ(r.faults_raised(), 1u);
  for (std::size_t k = 0; k < r.diagnoses.size(); ++k) {
    if (r.diagnoses[k].present && r.diagnoses[k].finding != Finding::LoadCellMissing) {
      ADD_FAILURE() << "corner " << k / 5 << " raised " << to_string(r.diagnoses[k].finding) << " at " << r.diagnoses[k].detected_s;
    }
  }
}

// A corner driven on its initial curve after a load-cell finding (13 % high on this caliper,
// tuning seed 1408 run 94). The switch from the load cell to the curve steps the feedback by 6 kN
// after the loop had pushed on 1 mrev against the bias: read as the caliper's stiffness, 1200
// kN/rev, it cut the loop's gain 80-fold, the hold backed off at 0.2-0.8 rev/s and the force
// integral learnt the error all the while; the release to 3 kN then ran 1.9 rev past the pads and
// the CCU named the healthy actuator actuator_tracking. With the shipped defaults the loop
// restarts its stiffness estimate and integral at the switch (controller.feedback_switch_restart):
// no actuator finding and the brake never off while 2 kN or more is commanded. The older option
// force_integral_max_speed_error_rev_per_s (2 rev/s, off by default) also prevents it alone.
TEST(ClosedLoopIssue14, AReleaseOnTheCurveAfterALoadCellFindingStopsAtThePads) {
  auto fs = load("config/scenarios/faults/load_cell_bias_in_hard_stop_then_release_on_the_curve.yaml");
  const auto fr = [](const LoopResult& r) { return actuator(r, 1); };
  const auto off_s = [](const LoopResult& r) {
    double s = 0.0;
    for (std::size_t k = 1; k < r.periods.size(); ++k) {
      const auto& p = r.periods[k];
      if (p.time_s > 2.3 && p.time_s < 3.0 && p.command_kN[1] >= 2.0 && p.true_kN[1] < 0.5) {
        s += p.time_s - r.periods[k - 1].time_s;
      }
    }
    return s;
  };
  ASSERT_TRUE(fs.scenario.controller.feedback_switch_restart);
  ASSERT_EQ(fs.scenario.controller.force_integral_max_speed_error_rev_per_s, 0.0);
  const auto expect_stops_at_the_pads = [&](const LoopResult& r, const char* what) {
    ASSERT_EQ(r.outcomes.size(), 1u) << what;
    EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct) << what;
    EXPECT_FALSE(fr(r).present) << what << ": " << to_string(fr(r).finding) << " at " << fr(r).detected_s;
    EXPECT_EQ(r.faults_raised(), 1u) << what;
    EXPECT_LT(off_s(r), 0.02) << what;
  };
  const auto r = run_closed_loop(fs, default_options());
  expect_stops_at_the_pads(r, "shipped");
  fs.scenario.controller.feedback_switch_restart = false;
  // (Left with the configured curve, as when the restart was made: with the caliper's own
  // end-of-line curve the curve it is left with is near enough that the loop does not wind up.)
  auto configured_start = default_options();
  configured_start.monitor.calibrator_initial_curve_from_eol = false;
  configured_start.monitor.lost_load_cell_curve_from_eol = false;
  const auto wound = run_closed_loop(fs, configured_start);
  EXPECT_GT(off_s(wound), 0.1);
  ASSERT_TRUE(fr(wound).present);
  fs.scenario.controller.force_integral_max_speed_error_rev_per_s = 2.0;
  expect_stops_at_the_pads(run_closed_loop(fs, configured_start), "the integral option alone");
  std::printf("brake off while >= 2 kN commanded: %.0f ms; without the restart at the switch %.0f ms and %s at %.3f s\n",
              1e3 * off_s(r), 1e3 * off_s(wound), to_string(fr(wound).finding), fr(wound).detected_s);
}

// A 62 % torque loss named, then a stuck load cell on the same corner (tuning seed 1401 run 334):
// in the hold that follows, the tests answer about 0.26 with a whole drive's noise; judged against
// the motor that is left, no two in a row look dead. Judged as a whole drive's, the drive was named
// lost 3 s later (the actuator's diagnosis upgraded from the torque loss).
TEST(ClosedLoopIssue14, AfterANamedTorqueLossTheTestsJudgeTheMotorThatIsLeft) {
  const auto fs = load("config/scenarios/faults/torque_loss_then_a_stuck_load_cell_in_a_hold.yaml");
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 2u);
  for (const auto& o : r.outcomes) EXPECT_TRUE(o.detected) << to_string(o.fault.type) << " " << to_string(o.diagnosis);
  EXPECT_EQ(r.faults_raised(), 2u);
  auto opts = default_options();
  opts.monitor.test_pulse_rescaled_after_loss = false;
  opts.monitor.calibrator_initial_curve_from_eol = false;  // (as when the rule was made)
  start_as_configured(opts.monitor);
  const auto base = run_closed_loop(fs, opts);
  const auto named_lost = [](const LoopResult& x) {
    for (const auto& d : x.diagnoses) {
      if (d.present && d.finding == Finding::ActuatorLost) return true;
    }
    return false;
  };
  EXPECT_FALSE(named_lost(r));
  EXPECT_TRUE(named_lost(base));  // RR's torque loss upgraded to actuator_lost
}

// A resolver stuck in a 37 kN hard stop (tuning seed 1403 run 420): the clamp back-drives the
// screw onto the retracted stop unseen, and the load cell's rise toward 0 at the stop (the
// spindle's friction vanishing, the pads off) is not named an offset while the resolver is named
// stuck. Judged as any step, it was.
TEST(ClosedLoopIssue14, TheMovingStepRuleLetsTheFrictionVanishWhileTheResolverIsNamedStuck) {
  const auto fs = load("config/scenarios/faults/resolver_stuck_released_onto_the_end_stop.yaml");
  const auto r = run_closed_loop(fs, default_options());
  ASSERT_EQ(r.outcomes.size(), 1u);
  EXPECT_TRUE(r.outcomes[0].detected && r.outcomes[0].correct) << to_string(r.outcomes[0].diagnosis);
  EXPECT_EQ(r.faults_raised(), 1u);
  auto opts = default_options();
  opts.monitor.step_moving_resolver_stuck_pads_off = true;
  const auto base = run_closed_loop(fs, opts);
  EXPECT_EQ(base.faults_raised(), 2u);  // + load_cell_offset on FR
  // A bias on the disc while the resolver is stuck is still a step the rule names, in 6 ms
  // (tuning seed 1403 run 624).
  const auto b = run_closed_loop(load("config/scenarios/faults/resolver_stuck_then_a_load_cell_bias_in_a_hard_stop.yaml"),
                                 default_options());
  ASSERT_EQ(b.outcomes.size(), 2u);
  for (const auto& o : b.outcomes) EXPECT_TRUE(o.detected) << to_string(o.fault.type) << " " << to_string(o.diagnosis);
  EXPECT_EQ(b.faults_raised(), 2u);
}

namespace {

// Each corner's RMS |estimate - clamp force| from from_s on (the periods the CCU estimated).
std::array<double, kCorners> estimate_rms_kN(const LoopResult& r, double from_s) {
  std::array<double, kCorners> sum{}, n{};
  for (const auto& p : r.periods) {
    if (p.time_s < from_s) continue;
    for (std::size_t c = 0; c < kCorners; ++c) {
      if (!std::isfinite(p.true_kN[c]) || !std::isfinite(p.estimate_kN[c])) continue;
      const double e = p.estimate_kN[c] - p.true_kN[c];
      sum[c] += e * e;
      n[c] += 1.0;
    }
  }
  std::array<double, kCorners> rms{};
  for (std::size_t c = 0; c < kCorners; ++c) rms[c] = n[c] > 0.0 ? std::sqrt(sum[c] / n[c]) : std::numeric_limits<double>::infinity();
  return rms;
}

}  // namespace

// Slow ramps on calipers three to ten times stiffer (stiff10_ff run 17), FR with load-dependent
// keys and RR with play: no hysteresis cycle until the end, so no calibrator fits before it, and the
// estimate was the load cell as it is, keys and all (2.8-3.7 kN RMS off). Started from each
// caliper's end-of-line keys, their growth with the load and the play (calibrator_start.friction_,
// load_friction_ and backlash_from_end_of_line), every corner's estimate is within a few tenths of
// a kN. Before the pads touched, the corners' load-cell loops stood on 3.6-3.8 kN of keys with the
// clamp force at 0: that is no actuator failing to track once the tracking rules count the friction
// the estimate took out (tracking.friction_as_subtracted); without, FL and FR were named.
TEST(ClosedLoopIssue14, ANeverFittedCalibratorStartsFromTheCalipersOwnKeys) {
  const char* scenario = "config/scenarios/faults/fault_free_stiff_calipers_slow_ramps_never_fitted.yaml";
  const auto fs = load(scenario);
  const auto r = run_closed_loop(fs, default_options());
  auto opts = default_options();
  opts.monitor.calibrator_friction_from_eol = false;
  opts.monitor.calibrator_load_friction_from_eol = false;
  opts.monitor.calibrator_backlash_from_eol = false;
  const auto raw = run_closed_loop(fs, opts);
  const auto with = estimate_rms_kN(r, 1.0), without = estimate_rms_kN(raw, 1.0);
  for (std::size_t c = 0; c < kCorners; ++c) {
    EXPECT_LE(r.fits[c], 1u) << "corner " << c;  // the premise: at most the end's one cycle to fit
    EXPECT_LT(with[c], 0.3) << "corner " << c;
    EXPECT_GT(without[c], 2.0) << "corner " << c;
    std::printf("corner %zu: estimate %.3f kN RMS from the end-of-line keys, %.3f from the load cell as it is\n", c,
                with[c], without[c]);
  }
  expect_quiet_only_with_the_rule(scenario, "the tracking rules counting the friction taken out",
                                  Finding::ActuatorTracking,
                                  [](MonitorParams& m) { m.tracking_friction_as_subtracted = false; });
}

// The simulated end-of-line test measures each caliper's keys exactly; a real line would not. With
// a measurement that is wrong in every way the keys' model has (another draw of the elements, their
// thresholds 1.5 x too wide and their force 25 % too high), the calibrators still start far closer
// to the clamp force than the load cell as it is, on the shipped fault-free stop (where the fits
// move the keys toward what the cycles show) and on the stiff calipers' slow ramps (where nothing
// is fitted). The shipped stop raises nothing. (The stiff calipers' ramps raise load_cell_offset on
// FL and FR: the residual rules' end-of-line key model, not the calibrator's start, takes the
// measurement as exact; started as configured they raise the same two.)
TEST(ClosedLoopIssue14, AnEndOfLineKeyMeasurementThatIsWrongStillBeatsTheLoadCellAsItIs) {
  for (const char* scenario : {"config/scenarios/faults/fault_free_stop.yaml",
                               "config/scenarios/faults/fault_free_stiff_calipers_slow_ramps_never_fitted.yaml"}) {
    const bool shipped = std::string(scenario).find("fault_free_stop") != std::string::npos;
    const auto fs = load(scenario);
    auto wrong = fs.scenario.plant.key_friction;
    wrong.structure_seed += 1;
    wrong.half_width_kN *= 1.25;
    wrong.threshold_median_rev *= 1.5;
    wrong.threshold_min_rev *= 1.5;
    wrong.threshold_max_rev *= 1.5;
    auto opts = default_options();
    opts.monitor.eol_key_friction = wrong;
    const auto r = run_closed_loop(fs, opts);
    if (shipped) {
      EXPECT_EQ(r.faults_raised(), 0u) << scenario;
    }
    for (std::size_t i = 0; i < r.diagnoses.size(); ++i) {
      if (r.diagnoses[i].present) {
        std::printf("  raised: corner %zu %s at %.3f s\n", i / 5, to_string(r.diagnoses[i].finding), r.diagnoses[i].detected_s);
      }
    }
    auto raw_opts = default_options();
    start_as_configured(raw_opts.monitor);
    const auto raw = run_closed_loop(fs, raw_opts);
    const auto exact = run_closed_loop(fs, default_options());
    const auto with = estimate_rms_kN(r, 1.0), without = estimate_rms_kN(raw, 1.0), right = estimate_rms_kN(exact, 1.0);
    for (std::size_t c = 0; c < kCorners; ++c) {
      EXPECT_LT(with[c], 0.5 * without[c]) << scenario << " corner " << c;
      std::printf("%s corner %zu: estimate %.3f kN RMS from a wrong end-of-line measurement, %.3f from the right one, "
                  "%.3f started as configured\n", scenario, c, with[c], right[c], without[c]);
    }
  }
}
