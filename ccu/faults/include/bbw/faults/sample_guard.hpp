// The CCU's corrupt-sample guard (docs/faults.md, "Corrupt samples"): a sample that is
// non-finite, out of range, or whose sequence or time does not move forward is never used for
// an estimate or a command; each is counted by reason. A load cell that gives no value (NaN)
// with the rest intact is a dropout: the sample is usable, its load-cell channel is not.
#pragma once

#include <array>
#include <cstdint>

#include "bbw/faults/reading.hpp"

namespace bbw::faults {

struct GuardLimits {
  double position_min_rev = -1.0;
  double position_max_rev = 10.0;
  double speed_abs_max_rev_per_s = 200.0;
  double load_cell_min_kN = -10.0;  // key friction (2 kN) + viscous friction at full speed (issue 14)
  double load_cell_max_kN = 80.0;
  double current_abs_max_A = 80.0;
  // Within one incarnation (between rejoins) a corner's sequence and time move forward by what
  // its rate allows; a forged sample far ahead would otherwise make every later honest sample
  // look like it went backwards.
  double max_sequence_jump = 20000.0;  // samples (20 s at 1 kHz)
  double max_time_jump_s = 20.0;

  void validate() const;  // throws std::invalid_argument naming the field
};

enum class SampleIssue : std::uint8_t {
  None,
  NonFinite,          // NaN or inf anywhere except a NaN load cell
  OutOfRange,
  Duplicate,          // the same sequence number again
  SequenceBackwards,  // a sequence number below the last one accepted
  TimeBackwards,      // time not after the last accepted sample's
  Jump,               // sequence or time far ahead of the last accepted sample's
};
inline constexpr std::size_t kSampleIssueCount = 7;
const char* to_string(SampleIssue i);

struct SampleCheck {
  SampleIssue issue = SampleIssue::None;
  bool load_cell_present = true;   // false for a dropout (or when the sample is unusable)
  bool usable() const { return issue == SampleIssue::None; }
};

class SampleGuard {
 public:
  explicit SampleGuard(const GuardLimits& limits);  // throws std::invalid_argument

  // load_cell_diagnosed: the CCU has named this corner's load cell faulty and no longer uses it.
  // Its value out of range (or infinite) then makes the load-cell channel absent, not the sample
  // corrupt: the position, speed and current still count (a drifting load cell at -13 kN made
  // every sample of a releasing brake corrupt, its estimate frozen at 16.6 kN; tuning seed 1401
  // run 62). Counted apart (load_cell_ignored).
  SampleCheck check(const CornerReading& r, bool load_cell_diagnosed = false);
  // The corner is back after it was lost. A new incarnation (a restarted process,
  // sequence_restarts): its sequence may start again. The same process after a lost link: its
  // sequence goes on, so it may not go back nor repeat, but it may jump ahead (the samples of the
  // outage were never delivered). Either way its time must still move forward (the scenario's
  // time base continues), and the next accepted sample restores every check.
  void rejoin(bool sequence_restarts = true);

  std::uint64_t count(SampleIssue i) const { return counts_[static_cast<std::size_t>(i)]; }
  std::uint64_t rejected() const;
  std::uint64_t load_cell_missing() const { return load_cell_missing_; }
  // Samples of a diagnosed load cell whose value was out of range or infinite (check()).
  std::uint64_t load_cell_ignored() const { return load_cell_ignored_; }
  std::uint64_t last_seq() const { return last_seq_; }
  const GuardLimits& limits() const { return limits_; }
  double last_time_s() const { return last_time_s_; }
  bool has_accepted() const { return have_last_; }

 private:
  GuardLimits limits_;
  bool have_last_ = false;
  bool seq_continuity_ = true;   // false after rejoin(true) until the next accepted sample
  bool jump_continuity_ = true;  // false after any rejoin() until the next accepted sample
  std::uint64_t last_seq_ = 0;
  double last_time_s_ = 0.0;
  std::array<std::uint64_t, kSampleIssueCount> counts_{};
  std::uint64_t load_cell_missing_ = 0;
  std::uint64_t load_cell_ignored_ = 0;
};

}  // namespace bbw::faults
