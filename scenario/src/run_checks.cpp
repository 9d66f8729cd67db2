#include "bbw/scenario/run_checks.hpp"

#include <cmath>
#include <cstdio>
#include <set>
#include <string>

namespace bbw::scenario {

namespace {

std::string fmt(double v, const char* spec) {
  char buf[64];
  std::snprintf(buf, sizeof buf, spec, v);
  return buf;
}

std::string bytes_text(double b) {
  if (b >= 1.0e12) return fmt(b / 1.0e12, "%.3g TB");
  if (b >= 1.0e9) return fmt(b / 1.0e9, "%.3g GB");
  return fmt(b / 1.0e6, "%.3g MB");
}

}  // namespace

void check_four_corner_run(const Scenario& s) {
  std::set<std::string> seen;
  for (std::size_t i = 0; i < s.corners.size(); ++i) {
    const CornerSpec& c = s.corners[i];
    const std::string key = "corners[" + std::to_string(i) + "].name";
    if (c.name != "FL" && c.name != "FR" && c.name != "RL" && c.name != "RR") {
      throw config::ConfigError(s.file, c.line, key,
                                "'" + c.name + "' is not a corner of a four-corner run (FL, FR, RL, RR); this "
                                "scenario is for ./bbw simulate, not ./bbw run");
    }
    if (!seen.insert(c.name).second) {
      throw config::ConfigError(s.file, c.line, key, "corner '" + c.name + "' is listed twice");
    }
  }
  if (s.corners.empty()) throw config::ConfigError(s.file, 0, "corners", "a run needs at least one corner");
}

RunEstimate estimate_run(const Scenario& s) {
  RunEstimate e;
  e.plant_steps = s.duration_s / s.plant_dt_s;
  const double corners = static_cast<double>(s.corners.size());
  e.samples = e.plant_steps * corners;
  const double periods = s.duration_s / s.ccu_period_s;
  // Per corner: the CCU's sample log and the corner's period log; plus the CCU's period log.
  e.output_bytes = e.samples * kBytesPerSampleLine + periods * (corners + 1.0) * kBytesPerPeriodLine;
  return e;
}

void check_run_size(const Scenario& s, const RunLimits& limits) {
  if (s.duration_s > limits.max_duration_s) {
    throw config::ConfigError(s.file, s.duration_line, "duration_s",
                              "a run of " + fmt(s.duration_s, "%g") + " s is longer than the limit of " +
                                  fmt(limits.max_duration_s, "%g") + " s (--allow-large accepts it)");
  }
  const RunEstimate e = estimate_run(s);
  if (!(e.output_bytes <= limits.max_output_bytes)) {
    throw config::ConfigError(s.file, s.duration_line, "duration_s",
                              "the run would write about " + bytes_text(e.output_bytes) + " (" +
                                  fmt(e.samples, "%.3g") + " samples: " + fmt(s.duration_s, "%g") + " s at plant_dt_s " +
                                  fmt(s.plant_dt_s, "%g") + " s, " + std::to_string(s.corners.size()) +
                                  " corners), more than the limit of " + bytes_text(limits.max_output_bytes) +
                                  " (--allow-large accepts it)");
  }
}

}  // namespace bbw::scenario
