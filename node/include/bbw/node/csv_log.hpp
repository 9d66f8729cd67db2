// CSV logs as observers of the node cores: the CCU's per-corner sample logs and period commands
// (CcuCsvLog), a corner's per-period truth and applied command (CornerPeriodsLog). Used by the DDS
// processes and the in-process runner alike, so both write the same bytes. Files live here, not in
// the nodes: header-only, and no source of the node library includes it.
#pragma once

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "bbw/node/ccu_node.hpp"
#include "bbw/node/corner_node.hpp"

namespace bbw::node {

inline constexpr const char* kCcuCsvHeader =
    "time_s,seq,block_seq,position_rev,speed_rev_per_s,force_internal_kN,force_external_kN,force_true_kN,"
    "temperature_C,motor_current_A,command,force_mode,estimate_kN,friction_kN,curve_kN,fused_kN,valid,"
    "calibrated,source,available,accepted\n";

// The CCU's logs: one CSV per corner (every sample and the CCU's conclusions) and the period
// commands. An observer of the node.
class CcuCsvLog final : public CcuObserver {
 public:
  CcuCsvLog(const std::string& dir, const CcuNode& node) {
    for (std::size_t i = 0; i < node.channels(); ++i) {
      const std::string file = dir + "/ccu_" + corner_name(node.channel(i).corner) + ".csv";
      std::FILE* f = std::fopen(file.c_str(), "w");
      if (f == nullptr) throw std::runtime_error(file + ": cannot write");
      std::fputs(kCcuCsvHeader, f);
      corner_csv_[node.channel(i).slot] = f;
    }
    const std::string file = dir + "/ccu_periods.csv";
    periods_csv_ = std::fopen(file.c_str(), "w");
    if (periods_csv_ == nullptr) throw std::runtime_error(file + ": cannot write");
    std::fputs("time_s,demand_total_kN,command_total_kN,cmd_FL,cmd_FR,cmd_RL,cmd_RR,avail_FL,avail_FR,avail_RL,avail_RR\n",
               periods_csv_);
  }
  ~CcuCsvLog() override {
    for (std::FILE* f : corner_csv_) {
      if (f != nullptr) std::fclose(f);
    }
    if (periods_csv_ != nullptr) std::fclose(periods_csv_);
  }
  CcuCsvLog(const CcuCsvLog&) = delete;
  CcuCsvLog& operator=(const CcuCsvLog&) = delete;

  void flush() {
    for (std::FILE* f : corner_csv_) {
      if (f != nullptr) std::fflush(f);
    }
    if (periods_csv_ != nullptr) std::fflush(periods_csv_);
  }

  void on_sample(const CornerChannel& ch, std::uint64_t block_seq, const msg::MeasurementSample& s,
                 const SampleOutcome& o, const faults::CornerView& view, bool accepted) override {
    std::FILE* f = corner_csv_[ch.slot];
    if (f == nullptr) return;
    // Shortest round-trip decimal form (std::to_chars): exact, and far cheaper than %.17g.
    char line[700];
    char* p = line;
    char* const last = line + sizeof(line);
    // One character is kept back for each separator, so a full buffer truncates, never overflows.
    auto put = [&](double v) {
      p = std::to_chars(p, last - 1, v).ptr;
      *p++ = ',';
    };
    auto put_u = [&](unsigned long long v) {
      p = std::to_chars(p, last - 1, v).ptr;
      *p++ = ',';
    };
    put(s.time_s());
    put_u(s.seq());
    put_u(block_seq);
    for (double v : {s.position_rev(), s.speed_rev_per_s(), s.force_internal_kN(), s.force_external_kN(),
                     s.force_true_kN(), s.temperature_C(), s.motor_current_A(), s.command()}) {
      put(v);
    }
    put_u((s.status() & msg::STATUS_FORCE_MODE) ? 1 : 0);
    const double nan = std::nan("");
    for (double v : {o.valid ? o.estimate_kN : nan, o.valid ? o.friction_kN : nan, o.valid ? o.curve_kN : nan,
                     o.valid ? o.fused_kN : nan}) {
      put(v);
    }
    put_u(o.valid ? 1 : 0);
    put_u(o.calibrated ? 1 : 0);
    put_u(static_cast<unsigned long long>(view.source));
    put_u(view.available ? 1 : 0);
    put_u(accepted ? 1 : 0);  // the sample guard let this sample through
    p[-1] = '\n';
    std::fwrite(line, 1, static_cast<std::size_t>(p - line), f);
  }

  void on_commands(double t, double demand_total_kN, double command_total_kN,
                   const std::array<CornerPlan, ccu::kSlots>& plans, const CcuCore& core) override {
    char line[512];
    int n = std::snprintf(line, sizeof(line), "%.6f,%.9g,%.9g", t, demand_total_kN, command_total_kN);
    for (std::size_t s = 0; s < ccu::kSlots; ++s) {
      const bool has = core.has(s);
      n += std::snprintf(line + n, sizeof(line) - static_cast<std::size_t>(n), has ? ",%.9g" : ",nan",
                         has && plans[s].mode == ccu::CommandMode::Force ? plans[s].clamp_force_kN : std::nan(""));
    }
    for (std::size_t s = 0; s < ccu::kSlots; ++s) {
      n += std::snprintf(line + n, sizeof(line) - static_cast<std::size_t>(n), ",%d",
                         core.has(s) && plans[s].available ? 1 : 0);
    }
    line[n++] = '\n';
    std::fwrite(line, 1, static_cast<std::size_t>(n), periods_csv_);
  }

 private:
  std::array<std::FILE*, ccu::kSlots> corner_csv_{};
  std::FILE* periods_csv_ = nullptr;
};

// The per-period CSV (truth and applied command): an observer of the node.
class CornerPeriodsLog final : public CornerObserver {
 public:
  CornerPeriodsLog(const std::string& file, std::uint32_t incarnation) {
    // A restarted process appends to its predecessor's log.
    f_ = std::fopen(file.c_str(), incarnation == 0 ? "w" : "a");
    if (f_ == nullptr) throw std::runtime_error(file + ": cannot write");
    if (incarnation == 0) std::fputs("time_s,force_true_kN,applied_kN,watchdog_mode,incarnation\n", f_);
  }
  ~CornerPeriodsLog() override { std::fclose(f_); }
  CornerPeriodsLog(const CornerPeriodsLog&) = delete;
  CornerPeriodsLog& operator=(const CornerPeriodsLog&) = delete;
  void on_period(const PeriodRecord& r) override {
    std::fprintf(f_, "%.6f,%.9g,%.9g,%d,%u\n", r.time_s, r.force_true_kN, r.applied_kN ? *r.applied_kN : std::nan(""),
                 static_cast<int>(r.watchdog_mode), r.incarnation);
  }
  void flush() { std::fflush(f_); }

 private:
  std::FILE* f_ = nullptr;
};

}  // namespace bbw::node
