#include "report.hpp"

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "bbw/common/json.hpp"
#include "bbw/common/plot.hpp"

namespace bbw::launch {

namespace {

std::string num(double v) {
  char b[64];
  std::snprintf(b, sizeof(b), "%.17g", v);
  return b;
}

std::string html_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (c == '&') o += "&amp;";
    else o += c;
  }
  return o;
}

}  // namespace

void write_report(const std::string& dir, const std::string& title, const std::vector<ReportCorner>& corners,
                  const std::string& summary_json, const std::vector<FaultResult>* faults,
                  const std::vector<Detection>* detections) {
  using bbw::plot::quote;
  // Columns of ccu_<corner>.csv: 1 time_s, 4 position_rev, 6 force_internal_kN, 8 force_true_kN,
  // 11 command, 12 force_mode, 13 estimate_kN, 16 fused_kN, 18 calibrated.
  std::string s = "set datafile separator ','\nset terminal pngcairo size 900,600\nset grid\nset key top left\n";
  for (const auto& rc : corners) {
    const std::string& c = rc.summary.corner;
    const std::string log = quote(dir + "/ccu_" + c + ".csv");
    s += "set output " + quote(dir + "/loop_" + c + ".png") + "\n";
    s += "set title 'Corner " + c + ": force against position with the calibrated curve'\n";
    s += "set xlabel 'position [rev]'\nset ylabel 'force [kN]'\n";
    s += "plot " + log + " using 4:6 every 5 with dots lc rgb '#1f77b4' title 'internal load cell', " + log +
         " using 4:8 every 5 with dots lc rgb '#2ca02c' title 'truth'";
    if (rc.calibrated) {
      s += ", [0:*] ((" + num(rc.curve.a) + "*x + " + num(rc.curve.b) + ")*x + " + num(rc.curve.c) + ")*x + " +
           num(rc.curve.d) + " with lines lw 2 lc rgb '#d62728' title 'calibrated curve'";
    }
    s += "\n";
    s += "set output " + quote(dir + "/time_" + c + ".png") + "\n";
    s += "set title 'Corner " + c + ": clamp-force estimate, truth and command'\n";
    s += "set xlabel 'time [s]'\nset ylabel 'force [kN]'\n";
    s += "plot " + log + " using 1:8 every 5 with lines lc rgb '#2ca02c' title 'truth', " + log +
         " using 1:($18 > 0.5 ? $16 : 1/0) every 5 with lines lc rgb '#d62728' title 'fused estimate', " + log +
         " using 1:($12 > 0.5 ? $11 : 1/0) every 5 with lines lc rgb '#000000' dt 2 title 'command'\n";
  }
  if (faults != nullptr) {
    // Timeline: total clamp force against demand; injections (red) and detections (blue).
    const std::string tl = quote(dir + "/timeline.csv");
    s += "set output " + quote(dir + "/timeline.png") + "\n";
    s += "set title 'Total clamp force against demand; injections (red) and detections (blue)'\n";
    s += "set xlabel 'time [s]'\nset ylabel 'total clamp force [kN]'\nunset arrow\n";
    for (const auto& f : *faults) {
      s += "set arrow from " + num(f.fault.at_s) + ", graph 0 to " + num(f.fault.at_s) +
           ", graph 1 nohead lc rgb '#d62728' dt 2\n";
    }
    if (detections != nullptr) {
      for (const auto& d : *detections) {
        s += "set arrow from " + num(d.detected_s) + ", graph 0 to " + num(d.detected_s) +
             ", graph 0.9 nohead lc rgb '#1f77b4'\n";
      }
    }
    s += "plot " + tl + " using 1:2 every ::1 with lines lc rgb '#000000' dt 2 title 'demand', " + tl +
         " using 1:3 every ::1 with lines lc rgb '#2ca02c' title 'delivered (sum of true forces)'\nunset arrow\n";
  }
  bbw::plot::run_gnuplot(s, dir + "/report.gp");

  std::ofstream f(dir + "/report.html");
  if (!f) throw std::runtime_error(dir + "/report.html: cannot write");
  f << "<!doctype html>\n<html><head><meta charset='utf-8'><title>" << html_escape(title)
    << "</title></head><body>\n<h1>" << html_escape(title) << "</h1>\n";
  f << "<table border='1' cellpadding='4'><tr><th>corner</th><th>fused estimate error max / RMS [kN]</th>"
       "<th>load cell error RMS [kN]</th><th>tracking error max / RMS [kN]</th></tr>\n";
  for (const auto& rc : corners) {
    const auto& m = rc.summary;
    char row[512];
    char est[128];
    if (m.samples_scored > 0) {
      std::snprintf(est, sizeof(est), "%.3f / %.3f</td><td>%.3f", m.fused_max_abs_error_kN, m.fused_rms_error_kN,
                    m.load_cell_rms_error_kN);
    } else {
      std::snprintf(est, sizeof(est), "(not scored)</td><td>(not scored)");
    }
    std::snprintf(row, sizeof(row),
                  "<tr><td>%s</td><td>%s</td><td>%s</td></tr>\n", m.corner.c_str(), est,
                  m.force_samples > 0
                      ? (std::to_string(m.tracking_max_abs_error_kN).substr(0, 6) + " / " +
                         std::to_string(m.tracking_rms_error_kN).substr(0, 6)).c_str()
                      : "(no force command)");
    f << row;
  }
  f << "</table>\n";
  if (faults != nullptr) {
    f << "<h2>Faults</h2>\n<img src='timeline.png'>\n";
    f << "<table border='1' cellpadding='4'><tr><th>corner</th><th>part</th><th>type</th><th>injected [s]</th>"
         "<th>detected [s]</th><th>latency [ms]</th><th>diagnosis</th><th>correct</th><th>reaction</th>"
         "<th>delivered / demanded</th></tr>\n";
    for (const auto& r : *faults) {
      char row[1024];
      std::snprintf(row, sizeof(row),
                    "<tr><td>%s</td><td>%s</td><td>%s</td><td>%.3f</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td>"
                    "<td>%s</td><td>%.3f</td></tr>\n",
                    faults::to_string(r.fault.target), faults::to_string(r.fault.part), faults::to_string(r.fault.type),
                    r.fault.at_s, r.detected ? std::to_string(r.detected_s).c_str() : "-",
                    r.detected ? std::to_string(r.latency_ms).substr(0, 6).c_str() : "-",
                    html_escape(faults::diagnosis_name(r)).c_str(), r.correct ? "yes" : "no", html_escape(r.reaction).c_str(),
                    r.delivered_share);
      f << row;
    }
    f << "</table>\n";
  }
  for (const auto& rc : corners) {
    const std::string& c = rc.summary.corner;
    f << "<h2>Corner " << c << "</h2>\n<img src='loop_" << c << ".png'> <img src='time_" << c << ".png'>\n";
  }
  f << "<h2>summary.json</h2>\n<pre>" << html_escape(summary_json) << "</pre>\n</body></html>\n";
}

}  // namespace bbw::launch
