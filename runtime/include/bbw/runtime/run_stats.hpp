// Run statistics: what bbw_ccu and bbw_corner leave for bbw_launch at their end (or at a
// scheduled kill), as typed structs with ONE serialiser/parser pair. The file is "key=value" per
// line in the order written (small enough to read without a JSON parser); the key list exists
// once, in run_stats.cpp (the field tables). Reading refuses a missing key, an unknown key, a
// repeated key and a malformed value, naming the file and the key.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace bbw::runtime {

// The CCU's view of one corner (keys "<corner>.<field>").
struct CcuCornerStats {
  std::string corner;  // FL, FR, RL, RR
  std::uint64_t blocks_received = 0;
  std::uint64_t samples_received = 0;
  std::uint64_t samples_invalid = 0;
  std::uint64_t foreign_blocks = 0;
  std::uint64_t foreign_health = 0;
  std::uint64_t blocks_over_rate = 0;
  std::uint64_t block_gaps = 0;
  std::uint64_t sample_gaps = 0;
  std::uint64_t rejoins = 0;
  std::uint64_t deadlines_missed = 0;
  std::uint64_t liveliness_lost = 0;
  std::uint64_t guard_rejected = 0;
  std::uint64_t load_cell_ignored = 0;  // a diagnosed load cell's values out of range: absent, the samples kept
  std::uint64_t calibrator_restarts = 0;
  std::uint64_t fits_accepted = 0;
  std::uint64_t fits_rejected = 0;
  std::uint64_t cycles_detected = 0;
  std::uint64_t samples_rejected = 0;
  double first_fit_time_s = 0.0;
  std::uint64_t calibration_version = 0;
  double curve_a = 0.0, curve_b = 0.0, curve_c = 0.0, curve_d = 0.0;
};

// One detection of the CCU's fault monitor (keys "detection.<i>.<field>"), in recording order.
struct DetectionStats {
  std::string corner;   // FL, FR, RL, RR
  std::string finding;  // faults::to_string(Finding)
  std::string part;     // faults::to_string(Part)
  double onset_s = 0.0;
  double detected_s = 0.0;
};

struct CcuRunStats {
  std::string mode;  // lockstep | realtime
  std::uint64_t periods_planned = 0;
  std::uint64_t periods_done = 0;
  double sim_s = 0.0;
  double wall_s = 0.0;
  double killed_at_s = -1.0;
  std::uint64_t measurement_deadlines_missed = 0;
  std::uint64_t measurement_liveliness_lost = 0;
  std::uint64_t measurement_samples_lost = 0;
  std::uint64_t qos_events_dropped = 0;
  std::uint64_t foreign_corner_samples = 0;
  std::uint64_t unknown_corner_blocks = 0;
  std::uint64_t foreign_run_samples = 0;
  std::string foreign_runs;  // dds::join_peer_tags
  std::uint64_t command_write_failures = 0;
  std::vector<CcuCornerStats> corners;      // key "corners": their names, comma-separated
  std::vector<DetectionStats> detections;   // key "detections": their count

  // The entry of `corner`; throws std::runtime_error naming `file` when there is none.
  const CcuCornerStats& corner(const std::string& corner, const std::string& file) const;
};

struct CornerRunStats {
  std::string corner;
  std::uint64_t incarnation = 0;
  std::uint64_t first_step = 0;
  std::uint64_t periods = 0;
  std::uint64_t samples_published = 0;
  std::uint64_t blocks_published = 0;
  std::uint64_t write_failures = 0;
  std::uint64_t commands_received = 0;
  std::uint64_t commands_applied = 0;
  std::uint64_t command_seq_gaps = 0;
  std::uint64_t calibrations_applied = 0;
  std::uint64_t calibrations_rejected = 0;
  std::uint64_t overruns = 0;
  double max_jitter_s = 0.0;
  double mean_jitter_s = 0.0;
  std::uint64_t command_deadlines_missed = 0;
  std::uint64_t samples_suppressed = 0;
  std::uint64_t samples_delayed = 0;
  std::uint64_t samples_in_flight = 0;
  std::uint64_t samples_without_ccu = 0;
  double ccu_lost_s = -1.0;
  double default_force_s = -1.0;
  double wall_s = 0.0;
  std::uint64_t commands_clamped = 0;
  std::uint64_t commands_refused_run = 0;
  std::uint64_t commands_refused_source = 0;
  std::uint64_t commands_refused_value = 0;
  double gate_max_force_kN = 0.0;
  std::string foreign_runs;  // dds::join_peer_tags
};

// The text of a stats file, and its parse (`file` names the source in errors).
std::string to_text(const CcuRunStats& s);
std::string to_text(const CornerRunStats& s);
CcuRunStats parse_ccu_stats(const std::string& text, const std::string& file);
CornerRunStats parse_corner_stats(const std::string& text, const std::string& file);

// Write / read a file. Throw std::runtime_error naming the file (and the key or line).
void save(const CcuRunStats& s, const std::string& file);
void save(const CornerRunStats& s, const std::string& file);
CcuRunStats load_ccu_stats(const std::string& file);
CornerRunStats load_corner_stats(const std::string& file);

}  // namespace bbw::runtime
