#include "bbw/runtime/run_stats.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace bbw::runtime {

namespace {

// The field tables: every key once, used by the writer and the reader alike.
template <class S, class F>
void ccu_fields(S& s, F&& f) {
  f("mode", s.mode);
  f("periods_planned", s.periods_planned);
  f("periods_done", s.periods_done);
  f("sim_s", s.sim_s);
  f("wall_s", s.wall_s);
  f("killed_at_s", s.killed_at_s);
  f("measurement_deadlines_missed", s.measurement_deadlines_missed);
  f("measurement_liveliness_lost", s.measurement_liveliness_lost);
  f("measurement_samples_lost", s.measurement_samples_lost);
  f("qos_events_dropped", s.qos_events_dropped);
  f("foreign_corner_samples", s.foreign_corner_samples);
  f("unknown_corner_blocks", s.unknown_corner_blocks);
  f("foreign_run_samples", s.foreign_run_samples);
  f("foreign_runs", s.foreign_runs);
  f("command_write_failures", s.command_write_failures);
}

template <class S, class F>
void ccu_corner_fields(S& s, F&& f) {
  f("blocks_received", s.blocks_received);
  f("samples_received", s.samples_received);
  f("samples_invalid", s.samples_invalid);
  f("foreign_blocks", s.foreign_blocks);
  f("foreign_health", s.foreign_health);
  f("blocks_over_rate", s.blocks_over_rate);
  f("block_gaps", s.block_gaps);
  f("sample_gaps", s.sample_gaps);
  f("rejoins", s.rejoins);
  f("deadlines_missed", s.deadlines_missed);
  f("liveliness_lost", s.liveliness_lost);
  f("guard_rejected", s.guard_rejected);
  f("load_cell_ignored", s.load_cell_ignored);
  f("calibrator_restarts", s.calibrator_restarts);
  f("fits_accepted", s.fits_accepted);
  f("fits_rejected", s.fits_rejected);
  f("cycles_detected", s.cycles_detected);
  f("samples_rejected", s.samples_rejected);
  f("first_fit_time_s", s.first_fit_time_s);
  f("calibration_version", s.calibration_version);
  f("curve_a", s.curve_a);
  f("curve_b", s.curve_b);
  f("curve_c", s.curve_c);
  f("curve_d", s.curve_d);
}

template <class S, class F>
void detection_fields(S& s, F&& f) {
  f("corner", s.corner);
  f("finding", s.finding);
  f("part", s.part);
  f("onset_s", s.onset_s);
  f("detected_s", s.detected_s);
}

template <class S, class F>
void corner_fields(S& s, F&& f) {
  f("corner", s.corner);
  f("incarnation", s.incarnation);
  f("first_step", s.first_step);
  f("periods", s.periods);
  f("samples_published", s.samples_published);
  f("blocks_published", s.blocks_published);
  f("write_failures", s.write_failures);
  f("commands_received", s.commands_received);
  f("commands_applied", s.commands_applied);
  f("command_seq_gaps", s.command_seq_gaps);
  f("calibrations_applied", s.calibrations_applied);
  f("calibrations_rejected", s.calibrations_rejected);
  f("overruns", s.overruns);
  f("max_jitter_s", s.max_jitter_s);
  f("mean_jitter_s", s.mean_jitter_s);
  f("command_deadlines_missed", s.command_deadlines_missed);
  f("samples_suppressed", s.samples_suppressed);
  f("samples_delayed", s.samples_delayed);
  f("samples_in_flight", s.samples_in_flight);
  f("samples_without_ccu", s.samples_without_ccu);
  f("ccu_lost_s", s.ccu_lost_s);
  f("default_force_s", s.default_force_s);
  f("wall_s", s.wall_s);
  f("commands_clamped", s.commands_clamped);
  f("commands_refused_run", s.commands_refused_run);
  f("commands_refused_source", s.commands_refused_source);
  f("commands_refused_value", s.commands_refused_value);
  f("gate_max_force_kN", s.gate_max_force_kN);
  f("foreign_runs", s.foreign_runs);
}

// Writing: "key=value\n", doubles with 17 significant digits (they read back exactly).
class Out {
 public:
  explicit Out(std::string prefix = "") : prefix_(std::move(prefix)) {}
  void operator()(const std::string& key, const std::string& v) { text += prefix_ + key + "=" + v + "\n"; }
  void operator()(const std::string& key, std::uint64_t v) { (*this)(key, std::to_string(v)); }
  void operator()(const std::string& key, double v) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.17g", v);
    (*this)(key, std::string(buf));
  }
  std::string text;

 private:
  std::string prefix_;
};

// Reading: every line parsed first (key=value, no key twice); then each field takes its key
// (missing: an error); keys no field took are unknown (an error).
class In {
 public:
  In(const std::string& text, std::string file) : file_(std::move(file)) {
    std::istringstream in(text);
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      if (line.empty()) continue;
      const auto eq = line.find('=');
      if (eq == std::string::npos || eq == 0) {
        throw std::runtime_error(file_ + ":" + std::to_string(n) + ": expected key=value");
      }
      if (!values_.emplace(line.substr(0, eq), line.substr(eq + 1)).second) {
        throw std::runtime_error(file_ + ":" + std::to_string(n) + ": key '" + line.substr(0, eq) + "' given twice");
      }
    }
  }
  std::string take(const std::string& key) {
    const auto it = values_.find(key);
    if (it == values_.end()) throw std::runtime_error(file_ + ": missing key '" + key + "'");
    std::string v = std::move(it->second);
    values_.erase(it);
    return v;
  }
  void field(const std::string& key, std::string& v) { v = take(key); }
  void field(const std::string& key, std::uint64_t& v) {
    const std::string s = take(key);
    char* end = nullptr;
    errno = 0;
    const unsigned long long x = std::strtoull(s.c_str(), &end, 10);
    if (s.empty() || s[0] == '-' || *end != '\0' || errno == ERANGE) {
      throw std::runtime_error(file_ + ": key '" + key + "' is not a count: '" + s + "'");
    }
    v = x;
  }
  void field(const std::string& key, double& v) {
    const std::string s = take(key);
    char* end = nullptr;
    const double x = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0') throw std::runtime_error(file_ + ": key '" + key + "' is not a number: '" + s + "'");
    v = x;
  }
  // Throws on the first key no field took.
  void expect_all_taken() const {
    if (!values_.empty()) throw std::runtime_error(file_ + ": unknown key '" + values_.begin()->first + "'");
  }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
  std::map<std::string, std::string> values_;
};

auto reader(In& in, const std::string& prefix) {
  return [&in, prefix](const char* key, auto& v) { in.field(prefix + key, v); };
}

std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> out;
  std::size_t start = 0;
  if (s.empty()) return out;
  for (;;) {
    const auto c = s.find(',', start);
    out.push_back(s.substr(start, c == std::string::npos ? std::string::npos : c - start));
    if (c == std::string::npos) break;
    start = c + 1;
  }
  return out;
}

std::string slurp(const std::string& file) {
  std::ifstream f(file);
  if (!f) throw std::runtime_error(file + ": cannot read (did the process finish?)");
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void write_file(const std::string& text, const std::string& file) {
  std::ofstream f(file);
  if (!f) throw std::runtime_error(file + ": cannot write");
  f << text;
  if (!f) throw std::runtime_error(file + ": write error");
}

}  // namespace

const CcuCornerStats& CcuRunStats::corner(const std::string& name, const std::string& file) const {
  for (const auto& c : corners) {
    if (c.corner == name) return c;
  }
  throw std::runtime_error(file + ": no statistics of corner " + name);
}

std::string to_text(const CcuRunStats& s) {
  Out out;
  auto w = [&out](const char* key, const auto& v) { out(key, v); };
  ccu_fields(s, w);
  std::string names;
  for (const auto& c : s.corners) names += (names.empty() ? "" : ",") + c.corner;
  out("corners", names);
  for (const auto& c : s.corners) {
    ccu_corner_fields(c, [&out, &c](const char* key, const auto& v) { out(c.corner + "." + key, v); });
  }
  out("detections", static_cast<std::uint64_t>(s.detections.size()));
  for (std::size_t i = 0; i < s.detections.size(); ++i) {
    const std::string p = "detection." + std::to_string(i) + ".";
    detection_fields(s.detections[i], [&out, &p](const char* key, const auto& v) { out(p + key, v); });
  }
  return out.text;
}

std::string to_text(const CornerRunStats& s) {
  Out out;
  corner_fields(s, [&out](const char* key, const auto& v) { out(key, v); });
  return out.text;
}

CcuRunStats parse_ccu_stats(const std::string& text, const std::string& file) {
  In in(text, file);
  CcuRunStats s;
  ccu_fields(s, reader(in, ""));
  for (const auto& name : split_commas(in.take("corners"))) {
    if (name.empty()) throw std::runtime_error(file + ": key 'corners' has an empty name");
    CcuCornerStats c;
    c.corner = name;
    ccu_corner_fields(c, reader(in, name + "."));
    s.corners.push_back(c);
  }
  std::uint64_t n = 0;
  in.field("detections", n);
  for (std::uint64_t i = 0; i < n; ++i) {
    DetectionStats d;
    detection_fields(d, reader(in, "detection." + std::to_string(i) + "."));
    s.detections.push_back(d);
  }
  in.expect_all_taken();
  return s;
}

CornerRunStats parse_corner_stats(const std::string& text, const std::string& file) {
  In in(text, file);
  CornerRunStats s;
  corner_fields(s, reader(in, ""));
  in.expect_all_taken();
  return s;
}

void save(const CcuRunStats& s, const std::string& file) { write_file(to_text(s), file); }
void save(const CornerRunStats& s, const std::string& file) { write_file(to_text(s), file); }
CcuRunStats load_ccu_stats(const std::string& file) { return parse_ccu_stats(slurp(file), file); }
CornerRunStats load_corner_stats(const std::string& file) { return parse_corner_stats(slurp(file), file); }

}  // namespace bbw::runtime
