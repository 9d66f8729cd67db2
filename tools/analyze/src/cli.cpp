#include "bbw/analyze/cli.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "bbw/common/csv.hpp"

namespace bbw::analyze {

std::string usage() {
  return "usage: bbw_analyze --input FILE.csv --out DIR [--config FILE.yaml]\n"
         "         [--time COL] [--position COL] [--force COL] [--truth COL|none]\n"
         "         [--temperature COL|none] [--velocity COL] [--acceleration COL]\n"
         "         [--channels A,B,...|none] [--allow-unsorted-time] [--calibrator FILE.yaml|none]\n"
         "defaults: time_s (or t_s), position_rev, force_internal_kN, truth force_external_kN and\n"
         "temperature temperature_C and velocity speed_rev_per_s when present; channels: every other\n"
         "column of the header except those whose name contains 'true' (simulator ground truth).\n"
         "Time must increase strictly; --allow-unsorted-time drops the lines where it does not\n"
         "and counts them.\n"
         "Friction: the online calibrator's element set (its config, default the shipped\n"
         "config/calibrator/robust.yaml) when the position is in rev or --calibrator is given;\n"
         "else, or with --calibrator none, Delta_max chosen on a grid of the position range.\n";
}

namespace {

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  std::istringstream in(s);
  while (std::getline(in, cur, ','))
    if (!cur.empty()) out.push_back(cur);
  return out;
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

}  // namespace

CliArgs parse_args(const std::vector<std::string>& args) {
  CliArgs a;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& k = args[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= args.size()) throw std::invalid_argument(k + " needs a value");
      return args[++i];
    };
    if (k == "--input") a.input = next();
    else if (k == "--out") a.out = next();
    else if (k == "--config") a.config = next();
    else if (k == "--calibrator") a.calibrator = next();
    else if (k == "--time") a.time_col = next();
    else if (k == "--position") a.position_col = next();
    else if (k == "--force") a.force_col = next();
    else if (k == "--truth") a.truth_col = next();
    else if (k == "--temperature") a.temperature_col = next();
    else if (k == "--velocity") a.velocity_col = next();
    else if (k == "--acceleration") a.acceleration_col = next();
    else if (k == "--allow-unsorted-time") a.allow_unsorted_time = true;
    else if (k == "--channels") {
      a.channels_given = true;
      const std::string v = next();
      if (v != "none") a.channels = split_list(v);
    } else throw std::invalid_argument("unknown argument '" + k + "'");
  }
  if (a.input.empty()) throw std::invalid_argument("--input is required");
  if (a.out.empty()) throw std::invalid_argument("--out is required");
  return a;
}

std::string unit_from_column(const std::string& column) {
  const auto p = column.rfind('_');
  if (p == std::string::npos || p + 1 >= column.size()) return "";
  return column.substr(p + 1);
}

LoadedRecording load_recording(const CliArgs& a) {
  LoadedRecording L;
  L.file = a.input;
  const auto header = csv::read_header(a.input);
  L.time_col = !a.time_col.empty() ? a.time_col : (contains(header, "time_s") || !contains(header, "t_s") ? "time_s" : "t_s");
  L.position_col = a.position_col.empty() ? "position_rev" : a.position_col;
  L.force_col = a.force_col.empty() ? "force_internal_kN" : a.force_col;
  auto optional_default = [&](const std::string& given, const std::string& fallback) -> std::string {
    if (given == "none") return "";
    if (!given.empty()) {
      if (!contains(header, given)) throw std::invalid_argument(a.input + ": no column '" + csv::printable(given) + "'");
      return given;
    }
    return contains(header, fallback) ? fallback : "";
  };
  L.truth_col = optional_default(a.truth_col, "force_external_kN");
  L.temperature_col = optional_default(a.temperature_col, "temperature_C");
  // Recordings written before the unit's one spelling (speed_rev_per_s) call it speed_rev_s.
  L.velocity_col = optional_default(a.velocity_col, "speed_rev_per_s");
  if (L.velocity_col.empty() && a.velocity_col.empty()) L.velocity_col = optional_default("", "speed_rev_s");
  L.acceleration_col = optional_default(a.acceleration_col, "");

  std::vector<std::string> used = {L.time_col, L.position_col, L.force_col, L.truth_col, L.temperature_col,
                                   L.velocity_col, L.acceleration_col};
  if (a.channels_given) {
    L.channel_cols = a.channels;
    for (const auto& ch : L.channel_cols)
      if (contains(used, ch)) throw std::invalid_argument("--channels: '" + ch + "' is already used as a model input");
  } else {
    for (const auto& h : header)
      if (!contains(used, h) && h.find("true") == std::string::npos) L.channel_cols.push_back(h);
  }

  csv::ReadOptions o;
  o.required = {L.time_col, L.position_col, L.force_col};
  for (const auto& c : {L.truth_col, L.temperature_col, L.velocity_col, L.acceleration_col})
    if (!c.empty()) o.required.push_back(c);
  for (const auto& c : L.channel_cols) o.required.push_back(c);
  o.time_column = L.time_col;
  o.allow_unsorted_time = a.allow_unsorted_time;
  const csv::Table t = csv::read(a.input, o);
  L.lines_read = t.lines_read;
  L.lines_rejected = t.lines_rejected;
  L.lines_unsorted_time = t.lines_unsorted_time;
  L.rejection_summary = t.rejection_summary();
  auto& r = L.rec;
  r.time_s = t.column(L.time_col);
  r.position = t.column(L.position_col);
  r.force = t.column(L.force_col);
  if (!L.truth_col.empty()) r.truth = t.column(L.truth_col);
  if (!L.temperature_col.empty()) r.temperature = t.column(L.temperature_col);
  if (!L.velocity_col.empty()) r.velocity = t.column(L.velocity_col);
  if (!L.acceleration_col.empty()) r.acceleration = t.column(L.acceleration_col);
  for (const auto& c : L.channel_cols) r.channels.push_back({c, t.column(c)});
  L.force_unit = unit_from_column(L.force_col);
  L.position_unit = unit_from_column(L.position_col);
  return L;
}

}  // namespace bbw::analyze
