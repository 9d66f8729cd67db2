#include "entry_points.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <variant>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/common/csv.hpp"
#include "bbw/common/strict_yaml.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/scenario/run_checks.hpp"

namespace bbw::fuzz {

namespace {

std::string text(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

void require(bool ok, const std::string& what) {
  if (!ok) throw InvariantBroken(what);
}

// Reads every key of a mapping the way a loader would, choosing the accessor by what the value
// converts to, then finish(). Exercises number/integer/boolean/string/numbers/map/maps and their
// error paths. `budget` bounds the work: aliases can make a small document a huge tree.
void walk(config::Reader& r, int depth, int& budget) {
  std::vector<std::string> keys;
  for (const auto& kv : r.node()) keys.push_back(kv.first.Scalar());
  bool finishable = true;
  for (const auto& k : keys) {
    if (--budget < 0) return;  // finish() not reached: the document is accepted as far as read
    const YAML::Node n = r.node()[k];
    if (n.IsNull()) {
      (void)r.number_or(k, 0.0);
    } else if (n.IsMap()) {
      config::Reader child = r.map(k);
      if (depth < 16) walk(child, depth + 1, budget);
    } else if (n.IsSequence()) {
      if (n.size() > 0 && n[0].IsMap()) {
        for (config::Reader& item : r.maps(k)) {
          if (depth < 16 && budget > 0) walk(item, depth + 1, budget);
        }
      } else if (n.size() > 0 && n[0].IsSequence()) {
        // Lists of [t, value] pairs are read from the node by their loader (scenario breakpoints);
        // the Reader has no accessor for them, so this mapping cannot be finished.
        finishable = false;
      } else {
        for (double x : r.numbers(k)) require(std::isfinite(x), "numbers() returned a non-finite value");
      }
    } else {
      const std::string& s = n.Scalar();
      std::int64_t i = 0;
      double d = 0.0;
      if (s == "true" || s == "false") {
        (void)r.boolean(k);
      } else if (YAML::convert<std::int64_t>::decode(n, i)) {
        require(r.integer(k, std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max()) == i,
                "integer() differs from yaml-cpp's conversion");
      } else if (YAML::convert<double>::decode(n, d)) {
        const double v = r.number(k, config::Range::any());
        require(std::isfinite(v), "number() returned a non-finite value");
      } else {
        require(r.string(k) == s, "string() differs from the scalar");
      }
    }
  }
  if (finishable) r.finish();
}

}  // namespace

Outcome csv(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(text(data, size));
  csv::ReadOptions o;
  o.required = {"t_s", "x"};
  o.optional = {"f", "x"};  // a duplicate of a required column is loaded once
  o.max_line_chars = 256;
  try {
    const csv::Table t = csv::read_stream(in, "fuzz.csv", o);
    require(t.rows() > 0, "accepted a table without rows");
    require(t.columns.size() == t.values.size(), "column names and value columns differ in number");
    require(t.columns.size() >= 2 && t.columns[0] == "t_s" && t.columns[1] == "x", "required columns not first");
    for (const auto& c : t.values) {
      require(c.size() == t.rows(), "columns of different lengths");
      for (double v : c) require(std::isfinite(v), "accepted a non-finite value");
    }
    require(t.lines_rejected <= t.lines_read, "more lines rejected than read");
    require(t.rows() + t.lines_rejected == t.lines_read, "rows + rejected != lines read");
    require(t.first_rejected_lines.size() <= 5 && t.first_rejected_lines.size() == t.first_rejected_reasons.size(),
            "rejection list inconsistent");
    (void)t.rejection_summary();
    return Outcome::Accepted;
  } catch (const csv::CsvError&) {
    return Outcome::Rejected;
  }
}

Outcome yaml(const std::uint8_t* data, std::size_t size) {
  try {
    config::Reader r = config::Reader::from_string(text(data, size), "fuzz.yaml");
    int budget = 20000;
    walk(r, 0, budget);
    return Outcome::Accepted;
  } catch (const config::ConfigError&) {
    return Outcome::Rejected;
  }
}

Outcome calib(const std::uint8_t* data, std::size_t size) {
  try {
    config::Reader r = config::Reader::from_string(text(data, size), "fuzz_calibrator.yaml");
    const calibration::CalibratorConfig c = calibration::read_config(r);
    r.finish();
    require(c.x_max_rev > c.x_min_rev && c.f_max_kN > c.f_min_kN, "accepted an empty range");
    require(std::isfinite(c.delta_max_rev) && c.delta_max_rev > 0, "accepted delta_max_rev <= 0");
    return Outcome::Accepted;
  } catch (const config::ConfigError&) {
    return Outcome::Rejected;
  }
}

Outcome scenario(const std::uint8_t* data, std::size_t size, const std::string& source_dir) {
  try {
    const scenario::Scenario s =
        scenario::load_scenario_string(text(data, size), source_dir + "/config/scenarios/fuzz.yaml");
    require(!s.corners.empty(), "accepted a scenario without corners");
    require(std::isfinite(s.duration_s) && s.duration_s > 0, "accepted a non-positive duration");
    require(s.plant_dt_s > 0 && s.ccu_period_s >= s.plant_dt_s, "accepted inconsistent time steps");
    return Outcome::Accepted;
  } catch (const config::ConfigError&) {
    return Outcome::Rejected;
  }
}

// The head every scenario_alias input continues: anchors a whole drive, a list of levels and
// a segment mapping, all valid, for the input to alias (or redefine) in any way. The input
// starts inside the first corner's mapping, so it can add keys, more corners, or top-level keys.
const char kAliasHead[] =
    "name: alias\n"
    "seed: 1\n"
    "duration_s: 2\n"
    "plant: ../plant/ecaliper.yaml\n"
    "corners:\n"
    "  - name: FL\n"
    "    temperature_C: 20\n"
    "    drive: &drive\n"
    "      mode: position\n"
    "      segments:\n"
    "        - &segment {type: local_loops, levels_rev: &levels [1, 2, 3], amplitude_rev: 0.2, period_s: 1}\n"
    "        - {type: steps, levels_rev: *levels, hold_s: 0.1}\n";

Outcome scenario_alias(const std::uint8_t* data, std::size_t size, const std::string& source_dir) {
  const std::string doc = kAliasHead + text(data, size);
  try {
    const scenario::Scenario s = scenario::load_scenario_string(doc, source_dir + "/config/scenarios/fuzz.yaml");
    require(!s.corners.empty(), "accepted a scenario without corners");
    // What a loader may hold is bounded by the document limits: the position profile's levels
    // come from lists of at most 20 000 entries, in at most 200 000 nodes.
    std::size_t levels = 0;
    for (const auto& c : s.corners) {
      for (const auto& seg : c.drive.position.segments) {
        if (const auto* l = std::get_if<scenario::LocalLoops>(&seg)) levels += l->levels_rev.size();
        if (const auto* st = std::get_if<scenario::Steps>(&seg)) levels += st->levels_rev.size();
      }
    }
    require(levels <= config::DocumentLimits{}.max_nodes, "loaded more levels than the document may hold");
    const scenario::RunEstimate e = scenario::estimate_run(s);
    require(e.samples >= e.plant_steps && e.output_bytes > 0, "inconsistent run estimate");
    try {
      scenario::check_four_corner_run(s);
      scenario::check_run_size(s);
    } catch (const config::ConfigError&) {
      // refused for a run: the documented outcome
    }
    return Outcome::Accepted;
  } catch (const config::ConfigError&) {
    return Outcome::Rejected;
  }
}

Outcome csv_quoted(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return Outcome::Rejected;
  const std::uint8_t mode = data[0];
  std::string body = text(data + 1, size - 1);
  if (mode & 1) body = "\xEF\xBB\xBF" + body;
  csv::ReadOptions o;
  o.required = {"t_s", "x"};
  o.optional = {"a,b", "q\"q"};  // names only a quoted header can hold
  o.max_line_chars = 256;
  if (mode & 2) o.time_column = "t_s";
  o.allow_unsorted_time = (mode & 4) != 0;
  std::istringstream in(body);
  try {
    const csv::Table t = csv::read_stream(in, "fuzz.csv", o);
    require(t.rows() > 0, "accepted a table without rows");
    for (const auto& c : t.values) {
      require(c.size() == t.rows(), "columns of different lengths");
      for (double v : c) require(std::isfinite(v), "accepted a non-finite value");
    }
    require(t.rows() + t.lines_rejected + t.lines_unsorted_time == t.lines_read,
            "rows + rejected + dropped != lines read");
    if (!o.time_column.empty()) {
      const auto& ts = t.column("t_s");
      for (std::size_t i = 1; i < ts.size(); ++i) require(ts[i] > ts[i - 1], "accepted time that does not increase");
    } else {
      require(t.lines_unsorted_time == 0, "dropped lines without a time column");
    }
    const std::string summary = t.rejection_summary();
    for (const char c : summary) require(c >= 0x20 && c < 0x7f, "non-printable byte in the rejection summary");
    return Outcome::Accepted;
  } catch (const csv::CsvError& e) {
    for (const char* p = e.what(); *p; ++p) {
      require(*p >= 0x20 && *p < 0x7f, "non-printable byte in a CSV error message");
    }
    return Outcome::Rejected;
  }
}

const std::vector<Target>& targets() {
  static const std::vector<Target> t{
      {"csv", [](const std::uint8_t* d, std::size_t n, const std::string&) { return csv(d, n); }},
      {"yaml", [](const std::uint8_t* d, std::size_t n, const std::string&) { return yaml(d, n); }},
      {"calib", [](const std::uint8_t* d, std::size_t n, const std::string&) { return calib(d, n); }},
      {"scenario", scenario},
      {"scenario_alias", scenario_alias},
      {"csv_quoted", [](const std::uint8_t* d, std::size_t n, const std::string&) { return csv_quoted(d, n); }},
  };
  return t;
}

}  // namespace bbw::fuzz
