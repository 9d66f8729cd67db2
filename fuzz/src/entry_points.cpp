#include "entry_points.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/common/csv.hpp"
#include "bbw/common/strict_yaml.hpp"
#include "bbw/scenario/load.hpp"

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

const std::vector<Target>& targets() {
  static const std::vector<Target> t{
      {"csv", [](const std::uint8_t* d, std::size_t n, const std::string&) { return csv(d, n); }},
      {"yaml", [](const std::uint8_t* d, std::size_t n, const std::string&) { return yaml(d, n); }},
      {"calib", [](const std::uint8_t* d, std::size_t n, const std::string&) { return calib(d, n); }},
      {"scenario", scenario},
  };
  return t;
}

}  // namespace bbw::fuzz
