// Behavioural targets of issue 5 in the in-memory closed loop (docs/faults.md, "Measured").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "closed_loop.hpp"

using namespace bbw::faults;
using namespace bbw::faults::test;

namespace {

FaultScenario load(const std::string& rel) { return load_fault_scenario(source_path(rel)); }

}  // namespace

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
      if (p.time_s > 6.0 && e > worst) {
        worst = e;
        worst_t = p.time_s;
      }
    }
  }
  std::array<double, kCorners> rmax{}, nmax{}, rhold{};
  for (const auto& p : r.periods) {
    for (std::size_t i = 0; i < kCorners; ++i) {
      if (p.time_s > 3.0 && std::isfinite(p.residual_kN[i])) rmax[i] = std::max(rmax[i], std::abs(p.residual_kN[i]));
      nmax[i] = std::max(nmax[i], p.noise_kN[i]);
      if (p.time_s > 6.0 && std::isfinite(p.residual_kN[i])) rhold[i] = std::max(rhold[i], std::abs(p.residual_kN[i]));
    }
  }
  for (std::size_t i = 0; i < kCorners; ++i) std::printf("corner %zu: max |residual| after 3 s %.3f kN, after 6 s %.3f kN, max noise %.3f kN\n", i, rmax[i], rhold[i], nmax[i]);
  std::printf("worst estimate error after 6 s: %.3f kN at %.3f s\n", worst, worst_t);
  EXPECT_EQ(r.faults_raised(), 0u);
}

namespace {

const std::vector<std::string>& campaign() {
  static const std::vector<std::string> names = {
      "load_cell_bias", "load_cell_drift", "load_cell_stuck", "load_cell_noise_burst", "load_cell_dropout",
      "resolver_offset", "resolver_stuck", "actuator_torque_loss", "actuator_total_loss", "network_silence",
      "network_delay", "process_kill", "ccu_kill"};
  return names;
}

}  // namespace

TEST(ClosedLoop, CampaignTable) {
  std::printf("%-24s %-6s %-10s %-12s %9s  %-22s %-7s %s\n", "scenario", "corner", "part", "type", "latency", "diagnosis",
              "correct", "delivered");
  for (const auto& n : campaign()) {
    const auto fs = load("config/scenarios/faults/" + n + ".yaml");
    const auto r = run_closed_loop(fs, default_options());
    for (const auto& o : r.outcomes) {
      std::printf("%-24s %-6s %-10s %-12s %7.1f ms  %-22s %-7s %.3f\n", n.c_str(), to_string(o.fault.target),
                  to_string(o.fault.part), to_string(o.fault.type), o.detected ? o.latency_ms : -1.0,
                  to_string(o.diagnosis), o.correct ? "yes" : "no", o.delivered_share);
    }
    for (std::size_t i = 0; i < kCorners; ++i) {
      for (std::size_t p = 0; p < 5; ++p) {
        const auto& d = r.diagnoses[i * 5 + p];
        if (d.present) std::printf("    corner %zu raised %s at %.3f s\n", i, to_string(d.finding), d.detected_s);
      }
    }
  }
}
