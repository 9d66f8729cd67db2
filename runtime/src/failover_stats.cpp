#include "bbw/runtime/failover_stats.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace bbw::runtime {

double mono_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

namespace {

template <class S, class F>
void ccu_fields(S& s, F&& f) {
  f("role", s.role);
  f("strength_initial", s.strength_initial);
  f("strength_final", s.strength_final);
  f("failure", s.failure);
  f("failed_sim_s", s.failed_sim_s);
  f("failed_mono_s", s.failed_mono_s);
  f("resumed_mono_s", s.resumed_mono_s);
  f("outages", s.outages);
  f("stalls", s.stalls);
  f("demoted_sim_s", s.demoted_sim_s);
  f("demoted_mono_s", s.demoted_mono_s);
  f("demote_reason", s.demote_reason);
  f("periods_done", s.periods_done);
  f("t0_mono_s", s.t0_mono_s);
}

template <class S, class F>
void corner_fields(S& s, F&& f) {
  f("corner", s.corner);
  f("commands_primary", s.commands_primary);
  f("commands_standby", s.commands_standby);
  f("commands_unknown", s.commands_unknown);
  f("commands_stale", s.commands_stale);
  f("max_gap_mono_ms", s.max_gap_mono_ms);
  f("max_gap_mono_at_sim_s", s.max_gap_mono_at_sim_s);
  f("max_gap_sim_ms", s.max_gap_sim_ms);
  f("max_gap_sim_at_s", s.max_gap_sim_at_s);
  f("last_command_mono_s", s.last_command_mono_s);
  f("stalls", s.stalls);
}

std::string format(double v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.9f", v);
  return b;
}
std::string format(std::uint64_t v) { return std::to_string(v); }
std::string format(std::uint32_t v) { return std::to_string(v); }
std::string format(const std::string& v) { return v; }

class Writer {
 public:
  template <class T>
  void operator()(const char* key, const T& v) { out_ << key << '=' << format(v) << '\n'; }
  std::string str() const { return out_.str(); }

 private:
  std::ostringstream out_;
};

using Map = std::map<std::string, std::string>;

Map parse_lines(const std::string& text, const std::string& file) {
  Map m;
  std::istringstream in(text);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty()) continue;
    const auto eq = line.find('=');
    if (eq == std::string::npos) throw std::runtime_error(file + ":" + std::to_string(n) + ": not key=value: '" + line + "'");
    m[line.substr(0, eq)] = line.substr(eq + 1);
  }
  return m;
}

class Reader {
 public:
  Reader(const Map& m, const std::string& file) : m_(m), file_(file) {}
  template <class T>
  void operator()(const char* key, T& v) { read(key, at(key), v); }
  const std::string& at(const std::string& key) const {
    const auto it = m_.find(key);
    if (it == m_.end()) throw std::runtime_error(file_ + ": key '" + key + "' is missing");
    return it->second;
  }

  void read(const std::string& key, const std::string& text, double& v) const {
    char* end = nullptr;
    v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0') bad(key, text, "a number");
  }
  template <class U, std::enable_if_t<std::is_unsigned_v<U>, int> = 0>
  void read(const std::string& key, const std::string& text, U& v) const {
    char* end = nullptr;
    const unsigned long long x = std::strtoull(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || text[0] == '-') bad(key, text, "an unsigned integer");
    v = static_cast<U>(x);
  }
  void read(const std::string&, const std::string& text, std::string& v) const { v = text; }
  [[noreturn]] void bad(const std::string& key, const std::string& text, const char* what) const {
    throw std::runtime_error(file_ + ": key '" + key + "' must be " + what + ", got '" + text + "'");
  }

 private:
  const Map& m_;
  std::string file_;
};

void write_file(const std::string& text, const std::string& file) {
  std::ofstream f(file);
  f << text;
  if (!f) throw std::runtime_error(file + ": cannot write");
}

std::string read_file(const std::string& file) {
  std::ifstream f(file);
  if (!f) throw std::runtime_error(file + ": cannot read");
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace

void note_corner_stall(CornerFailoverStats& s, double late_s, double now_mono_s) {
  const StallInterval x{now_mono_s - late_s, now_mono_s};
  if (!s.stall_intervals.empty() && s.stall_intervals.back().to_mono_s >= x.from_mono_s) {
    s.stall_intervals.back().to_mono_s = std::max(s.stall_intervals.back().to_mono_s, x.to_mono_s);
    return;
  }
  ++s.stalls;
  if (s.stall_intervals.size() < CcuFailoverStats::kMaxStallIntervals) s.stall_intervals.push_back(x);  // else counted only
}

namespace {

template <class S, class W>
void write_stalls(const S& s, W& w) {
  w("stall_intervals", static_cast<std::uint64_t>(s.stall_intervals.size()));
  for (std::size_t i = 0; i < s.stall_intervals.size(); ++i) {
    const std::string p = "stall" + std::to_string(i) + ".";
    w((p + "from_mono_s").c_str(), s.stall_intervals[i].from_mono_s);
    w((p + "to_mono_s").c_str(), s.stall_intervals[i].to_mono_s);
  }
}

template <class S, class R>
void read_stalls(S& s, R& r) {
  std::uint64_t n = 0;
  r("stall_intervals", n);
  if (n > CcuFailoverStats::kMaxStallIntervals || n > s.stalls) {
    r.bad("stall_intervals", std::to_string(n), "at most 64 and at most `stalls`");
  }
  for (std::uint64_t i = 0; i < n; ++i) {
    const std::string p = "stall" + std::to_string(i) + ".";
    StallInterval x;
    r((p + "from_mono_s").c_str(), x.from_mono_s);
    r((p + "to_mono_s").c_str(), x.to_mono_s);
    s.stall_intervals.push_back(x);
  }
}

}  // namespace

std::string to_text(const CcuFailoverStats& s) {
  Writer w;
  ccu_fields(s, w);
  write_stalls(s, w);
  return w.str();
}

std::string to_text(const CornerFailoverStats& s) {
  Writer w;
  corner_fields(s, w);
  write_stalls(s, w);
  w("switches", static_cast<std::uint64_t>(s.switches.size()));
  w("switches_dropped", s.switches_dropped);
  for (std::size_t i = 0; i < s.switches.size(); ++i) {
    const OwnerSwitch& x = s.switches[i];
    const std::string p = "switch" + std::to_string(i) + ".";
    w((p + "from").c_str(), x.from);
    w((p + "to").c_str(), x.to);
    w((p + "step").c_str(), x.step);
    w((p + "sim_s").c_str(), x.sim_s);
    w((p + "mono_s").c_str(), x.mono_s);
    w((p + "gap_ms").c_str(), x.gap_ms);
  }
  return w.str();
}

CcuFailoverStats parse_ccu_failover(const std::string& text, const std::string& file) {
  const Map m = parse_lines(text, file);
  CcuFailoverStats s;
  Reader r(m, file);
  ccu_fields(s, r);
  if (s.role != "primary" && s.role != "standby") r.bad("role", s.role, "primary or standby");
  read_stalls(s, r);
  return s;
}

CornerFailoverStats parse_corner_failover(const std::string& text, const std::string& file) {
  const Map m = parse_lines(text, file);
  CornerFailoverStats s;
  Reader r(m, file);
  corner_fields(s, r);
  read_stalls(s, r);
  std::uint64_t n = 0;
  r("switches", n);
  r("switches_dropped", s.switches_dropped);
  for (std::uint64_t i = 0; i < n; ++i) {
    const std::string p = "switch" + std::to_string(i) + ".";
    OwnerSwitch x;
    r((p + "from").c_str(), x.from);
    r((p + "to").c_str(), x.to);
    r((p + "step").c_str(), x.step);
    r((p + "sim_s").c_str(), x.sim_s);
    r((p + "mono_s").c_str(), x.mono_s);
    r((p + "gap_ms").c_str(), x.gap_ms);
    s.switches.push_back(x);
  }
  return s;
}

void save(const CcuFailoverStats& s, const std::string& file) { write_file(to_text(s), file); }
void save(const CornerFailoverStats& s, const std::string& file) { write_file(to_text(s), file); }
CcuFailoverStats load_ccu_failover(const std::string& file) { return parse_ccu_failover(read_file(file), file); }
CornerFailoverStats load_corner_failover(const std::string& file) { return parse_corner_failover(read_file(file), file); }

}  // namespace bbw::runtime
