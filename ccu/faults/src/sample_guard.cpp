#include "bbw/faults/sample_guard.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace bbw::faults {
namespace {

void require(bool ok, const char* field, double value, const char* rule) {
  if (!ok) throw std::invalid_argument(std::string("GuardLimits.") + field + " = " + std::to_string(value) + ": " + rule);
}

}  // namespace

void GuardLimits::validate() const {
  require(std::isfinite(position_min_rev), "position_min_rev", position_min_rev, "must be finite");
  require(std::isfinite(position_max_rev) && position_max_rev > position_min_rev, "position_max_rev",
          position_max_rev, "must be finite and > position_min_rev");
  require(std::isfinite(speed_abs_max_rev_per_s) && speed_abs_max_rev_per_s > 0.0, "speed_abs_max_rev_per_s",
          speed_abs_max_rev_per_s, "must be > 0");
  require(std::isfinite(load_cell_min_kN), "load_cell_min_kN", load_cell_min_kN, "must be finite");
  require(std::isfinite(load_cell_max_kN) && load_cell_max_kN > load_cell_min_kN, "load_cell_max_kN",
          load_cell_max_kN, "must be finite and > load_cell_min_kN");
  require(std::isfinite(current_abs_max_A) && current_abs_max_A > 0.0, "current_abs_max_A", current_abs_max_A,
          "must be > 0");
  require(std::isfinite(max_sequence_jump) && max_sequence_jump >= 1.0, "max_sequence_jump", max_sequence_jump,
          "must be >= 1");
  require(std::isfinite(max_time_jump_s) && max_time_jump_s > 0.0, "max_time_jump_s", max_time_jump_s, "must be > 0");
}

const char* to_string(SampleIssue i) {
  switch (i) {
    case SampleIssue::None: return "none";
    case SampleIssue::NonFinite: return "non_finite";
    case SampleIssue::OutOfRange: return "out_of_range";
    case SampleIssue::Duplicate: return "duplicate";
    case SampleIssue::SequenceBackwards: return "sequence_backwards";
    case SampleIssue::TimeBackwards: return "time_backwards";
    case SampleIssue::Jump: return "jump";
  }
  return "?";
}

SampleGuard::SampleGuard(const GuardLimits& limits) : limits_((limits.validate(), limits)) {}

std::uint64_t SampleGuard::rejected() const {
  std::uint64_t n = 0;
  for (std::size_t i = 1; i < kSampleIssueCount; ++i) n += counts_[i];
  return n;
}

void SampleGuard::rejoin(bool sequence_restarts) {
  jump_continuity_ = false;
  if (sequence_restarts) seq_continuity_ = false;
}

SampleCheck SampleGuard::check(const CornerReading& r, bool load_cell_diagnosed) {
  SampleCheck c;
  const bool lc_ignored = load_cell_diagnosed && !std::isnan(r.force_kN) &&
                          (!std::isfinite(r.force_kN) || r.force_kN < limits_.load_cell_min_kN ||
                           r.force_kN > limits_.load_cell_max_kN);
  const bool lc_nan = std::isnan(r.force_kN) || lc_ignored;  // (absent either way)
  const bool cmd_ok = std::isnan(r.force_command_kN) || std::isfinite(r.force_command_kN);
  if (!std::isfinite(r.time_s) || !std::isfinite(r.position_rev) || !std::isfinite(r.speed_rev_per_s) ||
      !std::isfinite(r.motor_current_A) || (!lc_nan && !std::isfinite(r.force_kN)) || !cmd_ok) {
    c.issue = SampleIssue::NonFinite;
  } else if (r.position_rev < limits_.position_min_rev || r.position_rev > limits_.position_max_rev ||
             std::abs(r.speed_rev_per_s) > limits_.speed_abs_max_rev_per_s ||
             std::abs(r.motor_current_A) > limits_.current_abs_max_A ||
             (!lc_nan && (r.force_kN < limits_.load_cell_min_kN || r.force_kN > limits_.load_cell_max_kN))) {
    c.issue = SampleIssue::OutOfRange;
  } else if (have_last_ && seq_continuity_ && r.seq == last_seq_) {
    c.issue = SampleIssue::Duplicate;
  } else if (have_last_ && seq_continuity_ && r.seq < last_seq_) {
    c.issue = SampleIssue::SequenceBackwards;
  } else if (have_last_ && !(r.time_s > last_time_s_)) {
    c.issue = SampleIssue::TimeBackwards;
  } else if (have_last_ && jump_continuity_ &&
             (static_cast<double>(r.seq - last_seq_) > limits_.max_sequence_jump ||
              r.time_s - last_time_s_ > limits_.max_time_jump_s)) {
    c.issue = SampleIssue::Jump;
  }
  ++counts_[static_cast<std::size_t>(c.issue)];
  if (!c.usable()) {
    c.load_cell_present = false;
    return c;
  }
  have_last_ = true;
  seq_continuity_ = true;
  jump_continuity_ = true;
  last_seq_ = r.seq;
  last_time_s_ = r.time_s;
  c.load_cell_present = !lc_nan;
  if (lc_ignored) {
    ++load_cell_ignored_;
  } else if (lc_nan) {
    ++load_cell_missing_;
  }
  return c;
}

}  // namespace bbw::faults
