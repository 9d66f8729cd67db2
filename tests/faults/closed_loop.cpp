#include "closed_loop.hpp"

#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/dds/convert.hpp"
#include "bbw/node/in_process.hpp"

namespace bbw::faults::test {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The period being recorded; the observers fill in what the nodes report during it.
struct Recorder final : node::CcuObserver {
  PeriodRecord** rec = nullptr;
  void on_sample(const node::CornerChannel&, std::uint64_t, const msg::MeasurementSample&, const ccu::SampleOutcome&,
                 const CornerView&, bool) override {}
  void on_commands(double, double, double, const std::array<ccu::CornerPlan, ccu::kSlots>& plans,
                   const ccu::CcuCore& core) override {
    for (std::size_t s = 0; s < kCorners; ++s) {
      if (!core.has(s)) continue;
      (*rec)->command_kN[s] = plans[s].clamp_force_kN;
      (*rec)->available[s] = plans[s].available;
    }
  }
};

struct CornerRecorder final : node::CornerObserver {
  PeriodRecord** rec = nullptr;
  std::size_t slot = 0;
  void on_period(const node::PeriodRecord& p) override {
    (*rec)->true_kN[slot] = p.force_true_kN;
    (*rec)->applied_kN[slot] = p.applied_kN.value_or(kNaN);
  }
};

}  // namespace

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

CornerReading reading_from(const scenario::CornerSample& s, msg::MeasurementSample& wire) {
  dds::to_msg(s, false, wire);
  return node::reading_from(wire);
}

LoopResult run_closed_loop(const FaultScenario& fs, const LoopOptions& options) {
  const scenario::Scenario& sc = fs.scenario;
  if (!sc.demand) throw std::invalid_argument("closed loop: the scenario needs a demand");
  node::InProcessOptions io;
  io.schedule = fs.faults;
  io.watchdog = options.watchdog;
  io.monitor = options.monitor;
  io.reactions.redistribute = options.redistribute;
  io.reactions.count_held_force = options.count_held_force;
  io.process_faults = true;
  node::InProcessRun run(sc, options.calibrator, io);

  PeriodRecord* current = nullptr;
  Recorder ccu_recorder;
  ccu_recorder.rec = &current;
  run.ccu().set_observer(&ccu_recorder);
  std::array<CornerRecorder, kCorners> corner_recorders;
  std::array<bool, kCorners> present{};
  for (std::size_t i = 0; i < run.corners(); ++i) {
    const std::size_t slot = run.ccu().channel(i).slot;
    corner_recorders[slot].rec = &current;
    corner_recorders[slot].slot = slot;
    run.set_corner_observer(i, &corner_recorders[slot]);
    present[slot] = true;
  }
  std::vector<msg::MeasurementSample> delivered, one;
  if (options.deliver) {
    run.set_block_tap([&](std::size_t channel, msg::MeasurementBlock& b) {
      const std::size_t slot = run.ccu().channel(channel).slot;
      delivered.clear();
      for (const msg::MeasurementSample& s : b.samples()) {
        one.clear();
        options.deliver(slot, s, one);
        delivered.insert(delivered.end(), one.begin(), one.end());
      }
      b.samples() = delivered;
    });
  }

  LoopResult out;
  out.periods.reserve(run.ccu().periods());
  for (std::uint64_t k = 0; k < run.ccu().periods(); ++k) {
    PeriodRecord& rec = out.periods.emplace_back();
    rec.true_kN.fill(kNaN);
    rec.applied_kN.fill(kNaN);
    rec.command_kN.fill(kNaN);
    rec.estimate_kN.fill(kNaN);
    rec.residual_kN.fill(kNaN);
    rec.residual_change_kN.fill(kNaN);
    rec.noise_kN.fill(kNaN);
    current = &rec;
    if (!run.step()) throw std::logic_error("closed loop: the run ended early");
    rec.time_s = run.ccu().period_end_s(k);
    rec.demand_total_kN = run.ccu().core().demand_total_kN(run.ccu().period_start_s(k));
    rec.ccu_alive = run.ccu_alive();
    for (std::size_t s = 0; s < kCorners; ++s) {
      if (std::isfinite(rec.true_kN[s])) rec.delivered_total_kN += rec.true_kN[s];
      if (!present[s] || !rec.ccu_alive) continue;
      const CornerSupervisor& sup = run.ccu().core().supervisor(s);
      rec.estimate_kN[s] = sup.view().force_estimate_kN;
      rec.residual_kN[s] = sup.monitor().last_residual_kN();
      rec.residual_change_kN[s] = sup.monitor().last_residual_change_kN();
      rec.noise_kN[s] = sup.monitor().last_noise_fraction();
    }
  }
  current = nullptr;
  run.ccu().set_observer(nullptr);
  for (std::size_t i = 0; i < run.corners(); ++i) run.set_corner_observer(i, nullptr);

  for (std::size_t s = 0; s < kCorners; ++s) {
    if (!present[s]) continue;
    const CornerSupervisor& sup = run.ccu().core().supervisor(s);
    out.guard_rejected[s] = sup.guard().rejected();
    out.calibrator_samples[s] = sup.samples_fed();
    out.calibrator_restarts[s] = sup.calibrator_restarts();
    out.fits[s] = sup.calibrator().stats().fits_accepted;
    for (std::size_t p = 0; p < 5; ++p) out.diagnoses[s * 5 + p] = sup.monitor().diagnosis(static_cast<Part>(p));
  }
  // Scored by the one fault scorer (bbw/faults/outcome.hpp) from the CCU node's detection log,
  // as bbw_launch scores a DDS run from ccu.stats.
  std::vector<DetectionEvent> events;
  for (const node::DetectionRecord& d : run.ccu().detections()) {
    events.push_back({static_cast<Target>(d.slot), d.finding, d.onset_s, d.detected_s});
  }
  for (const FaultSpec& f : fs.faults.faults) {
    const auto slot = corner_slot(f.target);
    if (slot && present[*slot]) out.outcomes.push_back(score_fault(f, events));
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
