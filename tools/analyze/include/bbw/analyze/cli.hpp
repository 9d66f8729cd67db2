// Command line of bbw_analyze and loading of the recording it names.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "bbw/analysis/analysis.hpp"

namespace bbw::analyze {

struct CliArgs {
  std::string input, out, config;
  // The online calibrator's config whose friction element set the model fits; "" = the shipped
  // config/calibrator/robust.yaml when the position is in rev, "none" = Delta_max on a grid.
  std::string calibrator;
  std::string time_col, position_col, force_col, truth_col, temperature_col, velocity_col, acceleration_col;
  bool channels_given = false;
  std::vector<std::string> channels;  // "--channels none" gives an empty list
  bool allow_unsorted_time = false;   // drop (and count) lines whose time does not increase
};

std::string usage();
// Throws std::invalid_argument naming the offending argument.
CliArgs parse_args(const std::vector<std::string>& args);

struct LoadedRecording {
  analysis::Recording rec;
  std::string file;
  std::string time_col, position_col, force_col, truth_col, temperature_col, velocity_col, acceleration_col;
  std::vector<std::string> channel_cols;
  std::string force_unit, position_unit;
  std::size_t lines_read = 0, lines_rejected = 0, lines_unsorted_time = 0;
  std::string rejection_summary;
};

// The unit suffix of a column name ("force_internal_kN" -> "kN", "qm_m" -> "m"), or "" if none.
std::string unit_from_column(const std::string& column);

// Reads the CSV: required time/position/force, optional truth/temperature/velocity/acceleration;
// channels default to every other column of the header. Throws csv::CsvError for a file the
// reader refuses (not a regular file, duplicate column, time not increasing, ...) and
// std::invalid_argument for a named column the header lacks.
LoadedRecording load_recording(const CliArgs& a);

}  // namespace bbw::analyze
