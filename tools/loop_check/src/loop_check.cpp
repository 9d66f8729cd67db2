#include "bbw/loop_check/loop_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bbw/common/corner.hpp"
#include "bbw/faults/outcome.hpp"
#include "bbw/node/in_process.hpp"

namespace bbw::loop_check {
namespace {

// Per-corner accumulator, fed every received sample in time order.
struct Accumulator {
  HoldOptions o;
  bool started = false;
  double last_t = 0.0, last_cmd = 0.0, last_load_cell = 0.0;
  double cmd_since_s = 0.0;           // the command has been constant since
  double force_lp = 0.0, current_lp = 0.0;
  double hold_min = 0.0, hold_max = 0.0;
  bool in_hold = false;
  double sum_f2 = 0.0, sum_i2 = 0.0, sum_e2 = 0.0, n = 0.0;
  CornerLoopStats out;

  void add(const msg::MeasurementSample& s) {
    const double t = s.time_s();
    const double cmd = s.command();
    if (!started) {
      started = true;
      force_lp = s.force_true_kN();
      current_lp = s.motor_current_A();
      last_t = t;
      last_cmd = cmd;
      cmd_since_s = t;
      last_load_cell = s.force_internal_kN();
      return;
    }
    const double dt = t - last_t;
    const double a = dt > 0.0 ? -std::expm1(-dt / o.high_pass_s) : 0.0;
    force_lp += a * (s.force_true_kN() - force_lp);
    current_lp += a * (s.motor_current_A() - current_lp);
    if (std::abs(cmd - last_cmd) > 1e-9) cmd_since_s = t;
    const bool hold = cmd >= o.min_command_kN && t - cmd_since_s >= o.settle_s;
    if (hold) {
      if (!in_hold) hold_min = hold_max = s.force_true_kN();
      hold_min = std::min(hold_min, s.force_true_kN());
      hold_max = std::max(hold_max, s.force_true_kN());
      out.force_pp_kN = std::max(out.force_pp_kN, hold_max - hold_min);
      const double fh = s.force_true_kN() - force_lp, ih = s.motor_current_A() - current_lp;
      const double e = cmd - s.force_true_kN();
      sum_f2 += fh * fh;
      sum_i2 += ih * ih;
      sum_e2 += e * e;
      n += 1.0;
      out.hold_s += dt;
      if (std::isfinite(s.force_internal_kN()) && std::isfinite(last_load_cell)) {
        out.load_cell_step_kN = std::max(out.load_cell_step_kN, std::abs(s.force_internal_kN() - last_load_cell));
      }
    }
    in_hold = hold;
    last_t = t;
    last_cmd = cmd;
    last_load_cell = s.force_internal_kN();
  }

  CornerLoopStats finish() {
    if (n > 0.0) {
      out.force_hp_rms_kN = std::sqrt(sum_f2 / n);
      out.current_hp_rms_A = std::sqrt(sum_i2 / n);
      out.hold_error_rms_kN = std::sqrt(sum_e2 / n);
    }
    return out;
  }
};

class Observer final : public node::CcuObserver {
 public:
  explicit Observer(const HoldOptions& o) {
    for (auto& a : acc_) a.o = o;
  }
  void on_sample(const node::CornerChannel& channel, std::uint64_t, const msg::MeasurementSample& sample,
                 const ccu::SampleOutcome&, const faults::CornerView&, bool) override {
    seen_[channel.slot] = true;
    acc_[channel.slot].out.corner = corner_name(channel.corner);
    acc_[channel.slot].add(sample);
  }
  void on_commands(double, double, double, const std::array<ccu::CornerPlan, ccu::kSlots>&,
                   const ccu::CcuCore&) override {}

  std::array<Accumulator, ccu::kSlots> acc_;
  std::array<bool, ccu::kSlots> seen_{};
};

}  // namespace

double LoopReport::worst_force_hp_rms_kN() const {
  double w = 0.0;
  for (const auto& c : corners) w = std::max(w, c.force_hp_rms_kN);
  return w;
}

std::size_t LoopReport::findings() const {
  std::size_t n = 0;
  for (const auto& c : corners) n += c.findings.size();
  return n;
}

LoopReport measure(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
                   const faults::MonitorParams& monitor, const HoldOptions& options) {
  node::InProcessOptions opt;
  opt.monitor = monitor;
  node::InProcessRun run(scenario, calibrator, opt);
  Observer obs(options);
  run.ccu().set_observer(&obs);
  run.run();
  run.ccu().set_observer(nullptr);
  LoopReport r;
  for (std::size_t slot = 0; slot < ccu::kSlots; ++slot) {
    if (!obs.seen_[slot]) continue;
    CornerLoopStats c = obs.acc_[slot].finish();
    for (const auto& d : run.ccu().detections()) {
      if (d.slot != slot) continue;
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s at %.3f s", faults::to_string(d.finding), d.detected_s);
      c.findings.emplace_back(buf);
    }
    r.corners.push_back(std::move(c));
  }
  return r;
}

}  // namespace bbw::loop_check
