// The corner's last line of defence against unsafe clamp-force commands, whatever their source
// (issue 17): a command is refused unless it belongs to this run (its run id) and comes from the
// CCU the corner matched at start: the first writer whose participant announced itself as this
// run's CCU is pinned, and only it is accepted from then on (with a hot-standby CCU: the first
// two such writers, max_sources = 2). (Without DDS Security that
// announcement is not authenticated: a process that copies it passes; with it, only the ccu
// identity may write commands at all.) An accepted
// force command is clamped to the caliper's rated range [0, max_force_kN] and its change to
// max_rate_kN_per_s of the time between its period and that of the previous accepted force
// command.
//
// Pure: no DDS, no clock. The corner process calls check() once per received command
// (corner_unit/process/corner_app.cpp, CornerApp::drain_inputs) and counts the verdicts.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

namespace bbw::corner {

struct CommandGateParams {
  double max_force_kN = 40.0;         // the caliper's rated clamp-force range [0, max]
  double max_rate_kN_per_s = 8000.0;  // the full range in one 5 ms CCU period
  // Command writers that may be pinned: 1, or 2 in a run with a hot-standby CCU (issue 16: the
  // primary's and the standby's; DDS exclusive ownership lets one through at a time).
  int max_sources = 1;
  void validate() const;              // throws std::invalid_argument naming the field
};

// Who sent a command: the run id it carries, its writer's 16-byte GUID, and whether the
// writer's participant announced itself as this run's CCU.
struct CommandSource {
  std::uint64_t run_id = 0;
  std::array<std::uint8_t, 16> writer{};
  bool announced_as_ccu = false;
};

enum class GateVerdict {
  Accepted,       // applied as sent
  Clamped,        // applied, force limited to the range and/or the rate
  RefusedRun,     // another run's command
  RefusedSource,  // not the pinned CCU writer (before one is pinned: not announced as the CCU)
  RefusedValue,   // force not a finite number
};

struct GateResult {
  GateVerdict verdict = GateVerdict::Accepted;
  double force_kN = 0.0;  // the force to apply (Accepted / Clamped)
  bool applies() const { return verdict == GateVerdict::Accepted || verdict == GateVerdict::Clamped; }
};

struct CommandGateCounts {
  std::uint64_t accepted = 0;
  std::uint64_t clamped = 0;
  std::uint64_t refused_run = 0;
  std::uint64_t refused_source = 0;
  std::uint64_t refused_value = 0;
  std::uint64_t refused() const { return refused_run + refused_source + refused_value; }
};

class CommandGate {
 public:
  CommandGate(std::uint64_t run_id, const CommandGateParams& params);

  // One received command. `force_mode`: a clamp-force set point (its force is limited);
  // otherwise (release, profile) only the source is checked, force_kN is passed through, and
  // the rate limit starts again from 0 kN. `time_s`: the period the command applies to (the
  // CCU's period start; in realtime commands arrive bunched, so arrival time would clamp honest
  // steps). Time that does not advance allows no change.
  GateResult check(const CommandSource& source, bool force_mode, double force_kN, double time_s);

  const CommandGateCounts& counts() const { return counts_; }
  bool pinned() const { return pinned_count_ == params_.max_sources; }
  const CommandGateParams& params() const { return params_; }

 private:
  std::uint64_t run_id_;
  CommandGateParams params_;
  std::array<std::array<std::uint8_t, 16>, 2> pinned_{};
  int pinned_count_ = 0;
  int last_source_ = -1;  // index into pinned_ of the last accepted command's writer
  std::optional<double> last_force_kN_;
  double last_time_s_ = 0.0;
  CommandGateCounts counts_;
};

}  // namespace bbw::corner
