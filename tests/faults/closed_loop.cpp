#include "closed_loop.hpp"

#include <cmath>
#include <cstdlib>
#include <memory>
#include <optional>
#include <stdexcept>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/faults/injector.hpp"
#include "bbw/faults/link_faults.hpp"
#include "bbw/scenario/corner_sim.hpp"

namespace bbw::faults::test {

std::string source_path(const std::string& rel) {
  const char* dir = std::getenv("BBW_SOURCE_DIR");
  return std::string(dir != nullptr ? dir : BBW_TEST_SOURCE_DIR) + "/" + rel;
}

LoopOptions default_options() {
  LoopOptions o;
  o.calibrator = calibration::load_config(source_path("config/calibrator/robust.yaml"));
  return o;
}

std::size_t LoopResult::faults_raised() const {
  std::size_t n = 0;
  for (const auto& d : diagnoses) n += d.present ? 1 : 0;
  return n;
}

CornerReading reading_from(const scenario::CornerSample& s, std::uint64_t seq_offset) {
  CornerReading r;
  r.seq = s.seq - seq_offset;
  r.time_s = s.time_s;
  r.position_rev = s.position_rev;
  r.speed_rev_per_s = s.speed_rev_s;
  r.load_cell_kN = s.force_internal_kN;
  r.motor_current_A = s.motor_current_A;
  r.temperature_C = s.temperature_C;
  r.force_command_kN =
      s.command_kind == scenario::CommandKind::Force ? s.command : std::numeric_limits<double>::quiet_NaN();
  return r;
}

namespace {

constexpr std::array<Target, kCorners> kTargets = {Target::FL, Target::FR, Target::RL, Target::RR};

struct Corner {
  std::size_t scenario_index = 0;
  std::unique_ptr<scenario::CornerSim> sim;
  std::unique_ptr<FaultInjector> injector;
  std::unique_ptr<LinkFaults> link;
  std::unique_ptr<CcuWatchdog> watchdog;
  DelayQueue<CornerReading, 4096> outbox;
  // The CCU's last command (what the corner received).
  std::optional<corner_unit::ForceFeedback> feedback;
  std::optional<scenario::CurveEstimate> curve;
  bool was_killed = false;
  double killed_at_s = 0.0;
  bool liveliness_reported = false;
  std::uint64_t seq_offset = 0;
};

}  // namespace

LoopResult run_closed_loop(const FaultScenario& fs, const LoopOptions& options) {
  const scenario::Scenario& sc = fs.scenario;
  if (!sc.demand) throw std::invalid_argument("closed loop: the scenario needs a demand");
  const double dt = sc.plant_dt_s;
  const auto steps_per_period = static_cast<std::size_t>(std::llround(sc.ccu_period_s / dt));
  const double period_s = static_cast<double>(steps_per_period) * dt;
  const auto periods = static_cast<std::size_t>(std::floor(sc.duration_s / period_s + 1e-9));

  MonitorParams mp = options.monitor;
  const auto act = scenario::actuator_model(sc.plant);
  mp.torque_per_A_Nm = act.torque_per_A_Nm;
  mp.Nm_per_kN = act.Nm_per_kN;
  mp.inertia_kg_m2 = act.inertia_kg_m2;

  std::array<Corner, kCorners> corners;
  for (std::size_t i = 0; i < kCorners; ++i) {
    const char* name = to_string(kTargets[i]);
    std::size_t idx = sc.corners.size();
    for (std::size_t k = 0; k < sc.corners.size(); ++k) {
      if (sc.corners[k].name == name) idx = k;
    }
    if (idx == sc.corners.size()) throw std::invalid_argument(std::string("closed loop: no corner ") + name);
    Corner& c = corners[i];
    c.scenario_index = idx;
    c.sim = std::make_unique<scenario::CornerSim>(sc, idx);
    c.injector = std::make_unique<FaultInjector>(fs.faults, kTargets[i], scenario::corner_seed(sc.seed + 7777, idx));
    c.link = std::make_unique<LinkFaults>(fs.faults, kTargets[i]);
    c.watchdog = std::make_unique<CcuWatchdog>(options.watchdog);
  }
  const LinkFaults ccu_link(fs.faults, Target::CCU);
  auto make_ccu = [&] {
    std::array<std::unique_ptr<CornerSupervisor>, kCorners> s;
    for (std::size_t i = 0; i < kCorners; ++i) s[i] = std::make_unique<CornerSupervisor>(options.calibrator, mp, kTargets[i]);
    return s;
  };
  auto ccu = make_ccu();
  bool ccu_was_dead = false;
  const Redistributor redistributor(sc.demand->front_share);
  const scenario::BreakpointProfile demand(sc.demand->profile);
  const double total_per_demand_kN = 2.0 * sc.demand->max_clamp_force_kN / sc.demand->front_share;

  LoopResult out;
  out.periods.reserve(periods);
  std::vector<CornerReading> delivered;
  for (std::size_t k = 0; k < periods; ++k) {
    const double t0 = static_cast<double>(k) * period_s;
    const double t1 = t0 + period_s;
    PeriodRecord rec;
    rec.time_s = t1;
    const bool ccu_alive = !ccu_link.killed(t0);
    rec.ccu_alive = ccu_alive;
    if (ccu_alive && ccu_was_dead) ccu = make_ccu();  // a restarted CCU starts from its config
    ccu_was_dead = !ccu_alive;

    // The CCU commands for this period.
    const double demand_total = total_per_demand_kN * demand.at(t1).value;
    rec.demand_total_kN = demand_total;
    if (ccu_alive) {
      std::array<CornerCapacity, kCorners> cap;
      for (std::size_t i = 0; i < kCorners; ++i) {
        const CornerView& v = ccu[i]->view();
        cap[i] = {options.redistribute ? v.available : true, v.force_limit_kN, options.count_held_force ? v.held_kN : 0.0};
        rec.available[i] = v.available;
      }
      const Allocation a = redistributor.allocate(demand_total, cap);
      for (std::size_t i = 0; i < kCorners; ++i) {
        const CornerView& v = ccu[i]->view();
        rec.command_kN[i] = a.force_kN[i];
        corners[i].watchdog->on_command(t0, a.force_kN[i]);
        corners[i].feedback = v.feedback;
        if (v.feedback == corner_unit::ForceFeedback::Curve) {
          corners[i].curve = scenario::CurveEstimate{v.curve.a, v.curve.b, v.curve.c, v.curve.d};
        } else {
          corners[i].curve.reset();
        }
      }
    } else {
      rec.command_kN.fill(std::numeric_limits<double>::quiet_NaN());
    }

    // The corners run the period.
    for (std::size_t i = 0; i < kCorners; ++i) {
      Corner& c = corners[i];
      for (std::size_t s = 0; s < steps_per_period; ++s) {
        const double t = c.sim->time_s();
        const double t_end = t + dt;
        const bool killed = c.link->killed(t_end);
        if (killed && !c.was_killed) {
          c.killed_at_s = t_end;
          c.liveliness_reported = false;
        }
        if (!killed && c.was_killed) {
          c.seq_offset = c.sim->last().seq;  // a new incarnation counts from 1 again
          c.watchdog = std::make_unique<CcuWatchdog>(options.watchdog);
        }
        c.was_killed = killed;
        scenario::ExternalInputs ext;
        const WatchdogOutput w = c.watchdog->at(t_end);
        ext.force_command_kN = w.force_command_kN;
        rec.applied_kN[i] = w.force_command_kN.value_or(std::numeric_limits<double>::quiet_NaN());
        ext.feedback = c.feedback;
        ext.curve = c.curve;
        c.injector->prepare(ext, t_end);
        if (killed) ext.torque_scale = 0.0;  // a dead process leaves the motor unpowered
        const scenario::CornerSample& smp = c.sim->step(dt, ext);
        if (killed || c.link->silenced(smp.time_s)) continue;
        c.outbox.push(smp.time_s + c.link->delay_s(smp.time_s), reading_from(smp, c.seq_offset));
      }
      rec.true_kN[i] = c.sim->last().force_true_kN;
      rec.delivered_total_kN += rec.true_kN[i];
    }

    // The CCU receives what is due.
    for (std::size_t i = 0; i < kCorners; ++i) {
      Corner& c = corners[i];
      if (!ccu_alive) {
        while (c.outbox.pop_due(t1)) {
        }
        continue;
      }
      while (auto r = c.outbox.pop_due(t1 + 1e-12)) {
        delivered.clear();
        if (options.deliver) {
          options.deliver(i, *r, delivered);
        } else {
          delivered.push_back(*r);
        }
        for (const CornerReading& d : delivered) ccu[i]->on_sample(d, t1);
      }
      if (c.was_killed && !c.liveliness_reported && t1 - c.killed_at_s >= options.liveliness_lease_s) {
        c.liveliness_reported = true;
        ccu[i]->on_link_event(LinkEvent::LivelinessLost, t1);
      }
      ccu[i]->tick(t1);
      rec.estimate_kN[i] = ccu[i]->view().force_estimate_kN;
      rec.residual_kN[i] = ccu[i]->monitor().last_residual_kN();
      rec.residual_change_kN[i] = ccu[i]->monitor().last_residual_change_kN();
      rec.noise_kN[i] = ccu[i]->monitor().last_noise_fraction();
    }
    out.periods.push_back(rec);
  }

  for (std::size_t i = 0; i < kCorners; ++i) {
    const CornerSupervisor& s = *ccu[i];
    out.guard_rejected[i] = s.guard().rejected();
    out.calibrator_samples[i] = s.samples_fed();
    out.calibrator_restarts[i] = s.calibrator_restarts();
    out.fits[i] = s.calibrator().stats().fits_accepted;
    for (std::size_t p = 0; p < 5; ++p) out.diagnoses[i * 5 + p] = s.monitor().diagnosis(static_cast<Part>(p));
    for (const FaultSpec& f : fs.faults.faults) {
      if (f.target == kTargets[i]) out.outcomes.push_back(assess(f, s.monitor()));
    }
  }
  // Share of the demanded total delivered while each fault lasted.
  for (FaultOutcome& o : out.outcomes) {
    double d = 0.0, g = 0.0;
    for (const PeriodRecord& p : out.periods) {
      if (p.time_s < o.fault.at_s || p.time_s >= o.fault.end_s()) continue;
      d += p.demand_total_kN;
      g += p.delivered_total_kN;
    }
    o.delivered_share = d > 0.0 ? g / d : 1.0;
  }
  return out;
}

double recovery_time_s(const LoopResult& r, double fraction, double t_from, double t_to, double achievable_limit_kN) {
  double since = -1.0;
  for (const PeriodRecord& p : r.periods) {
    if (p.time_s < t_from || p.time_s > t_to) continue;
    const double target = fraction * std::min(p.demand_total_kN, achievable_limit_kN);
    if (p.delivered_total_kN >= target) {
      if (since < 0.0) since = p.time_s;
    } else {
      since = -1.0;
    }
  }
  return since;
}

}  // namespace bbw::faults::test
