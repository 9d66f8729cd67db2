#include "run_result.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "bbw/common/csv.hpp"
#include "bbw/common/json.hpp"
#include "draw.hpp"

namespace bbw::campaign {

namespace {

double magnitude_of(const faults::FaultSpec& f) {
  switch (f.type) {
    case faults::FaultType::Bias: return f.bias_kN;
    case faults::FaultType::Drift: return f.rate_kN_per_s;
    case faults::FaultType::NoiseBurst: return f.rms_kN;
    case faults::FaultType::Offset: return f.offset_rev;
    case faults::FaultType::TorqueLoss: return f.torque_loss_percent;
    case faults::FaultType::Delay: return f.delay_ms;
    default: return 0.0;
  }
}

}  // namespace

void score_into(RunResult& r, const std::vector<faults::FaultSpec>& specs, const std::vector<std::string>& kinds,
                const std::vector<std::string>& onsets, const std::vector<faults::DetectionEvent>& detections,
                const std::string& out_dir, double run_end_s) {
  const faults::RunScore score = faults::score_run(specs, detections, run_end_s);
  for (const auto& d : score.false_alarms) {
    r.false_alarms.push_back({faults::to_string(d.corner), faults::to_string(d.finding), d.detected_s});
  }
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const faults::FaultOutcome& o = score.outcomes.at(i);
    FaultRow row;
    row.kind = kinds.at(i);
    row.onset = onsets.at(i);
    row.corner = faults::to_string(o.fault.target);
    row.at_s = o.fault.at_s;
    row.end_s = std::min(o.fault.end_s(), run_end_s);
    row.magnitude = magnitude_of(o.fault);
    row.detected = o.detected;
    row.correct = o.correct;
    row.latency_ms = o.detected ? o.latency_ms : -1.0;
    row.diagnosis = faults::diagnosis_name(o);
    row.window_s = faults::detection_window_s(o.fault);
    row.masked = o.masked;
    row.observable_s = o.observable_s;
    row.above_limit = above_limit(row.kind, row.magnitude, row.at_s, row.end_s);
    // Harm while undetected, from the CCU's log of the corner.
    csv::ReadOptions opt;
    opt.required = {"time_s", "force_true_kN", "command", "force_mode", "fused_kN"};
    const auto t = csv::read(out_dir + "/ccu_" + row.corner + ".csv", opt);
    const double until_s = o.detected ? o.detected_s : row.end_s;
    const auto& time = t.column("time_s");
    const auto& truth = t.column("force_true_kN");
    const auto& cmd = t.column("command");
    const auto& mode = t.column("force_mode");
    const auto& est = t.column("fused_kN");
    if (o.detected) row.after_estimate_error_kN = 0.0;
    for (std::size_t k = 0; k < t.rows(); ++k) {
      if (o.detected && time[k] > o.detected_s && std::isfinite(est[k]) && std::isfinite(truth[k])) {
        row.after_estimate_error_kN = std::max(row.after_estimate_error_kN, std::abs(est[k] - truth[k]));
      }
      if (time[k] < row.at_s || time[k] > until_s) continue;
      if (mode[k] > 0.5) row.harm_force_error_kN = std::max(row.harm_force_error_kN, std::abs(truth[k] - cmd[k]));
      row.harm_estimate_error_kN = std::max(row.harm_estimate_error_kN, std::abs(est[k] - truth[k]));
    }
    r.faults.push_back(row);
  }
}

void save_result(const RunResult& r, const std::string& file) {
  json::Writer j;
  j.begin_object()
      .value("index", r.index)
      .value("fault_free", r.fault_free)
      .value("profile", r.profile)
      .value("transport", r.transport)
      .value("host", r.host)
      .value("duration_s", r.duration_s)
      .value("wall_s", r.wall_s)
      .value("ok", r.ok)
      .value("error", r.error);
  j.begin_array("faults");
  for (const FaultRow& f : r.faults) {
    j.begin_object()
        .value("kind", f.kind)
        .value("onset", f.onset)
        .value("corner", f.corner)
        .value("at_s", f.at_s)
        .value("end_s", f.end_s)
        .value("magnitude", f.magnitude)
        .value("above_limit", f.above_limit)
        .value("masked", f.masked)
        .value("observable_s", f.observable_s)
        .value("detected", f.detected)
        .value("correct", f.correct)
        .value("latency_ms", f.latency_ms)
        .value("diagnosis", f.diagnosis)
        .value("window_s", f.window_s)
        .value("harm_force_error_kN", f.harm_force_error_kN)
        .value("harm_estimate_error_kN", f.harm_estimate_error_kN)
        .value("after_estimate_error_kN", f.after_estimate_error_kN)
        .end_object();
  }
  j.end_array();
  j.begin_array("false_alarms");
  for (const FalseAlarmRow& a : r.false_alarms) {
    j.begin_object().value("corner", a.corner).value("finding", a.finding).value("detected_s", a.detected_s).end_object();
  }
  j.end_array();
  j.end_object();
  const std::string tmp = file + ".tmp";
  j.save(tmp);
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) throw std::runtime_error(file + ": cannot rename " + tmp + " (" + ec.message() + ")");
}

RunResult load_result(const std::string& file) {
  try {
    const YAML::Node n = YAML::LoadFile(file);  // JSON is YAML
    RunResult r;
    r.index = n["index"].as<int>();
    r.fault_free = n["fault_free"].as<bool>();
    r.profile = n["profile"].as<std::string>();
    r.transport = n["transport"].as<std::string>();
    r.host = n["host"].as<std::string>();
    r.duration_s = n["duration_s"].as<double>();
    r.wall_s = n["wall_s"].as<double>();
    r.ok = n["ok"].as<bool>();
    r.error = n["error"].as<std::string>();
    for (const auto& f : n["faults"]) {
      FaultRow row;
      row.kind = f["kind"].as<std::string>();
      row.onset = f["onset"].as<std::string>();
      row.corner = f["corner"].as<std::string>();
      row.at_s = f["at_s"].as<double>();
      row.end_s = f["end_s"].as<double>();
      row.magnitude = f["magnitude"].as<double>();
      row.above_limit = f["above_limit"].as<bool>();
      row.masked = f["masked"].as<bool>();  // a result written before masking was scored: run it again
      row.observable_s = f["observable_s"].as<double>();
      row.detected = f["detected"].as<bool>();
      row.correct = f["correct"].as<bool>();
      row.latency_ms = f["latency_ms"].as<double>();
      row.diagnosis = f["diagnosis"].as<std::string>();
      row.window_s = f["window_s"].as<double>();
      row.harm_force_error_kN = f["harm_force_error_kN"].as<double>();
      row.harm_estimate_error_kN = f["harm_estimate_error_kN"].as<double>();
      // (Absent from results written before it was measured: not measured.)
      if (f["after_estimate_error_kN"] && !f["after_estimate_error_kN"].IsNull()) row.after_estimate_error_kN = f["after_estimate_error_kN"].as<double>();
      r.faults.push_back(row);
    }
    for (const auto& a : n["false_alarms"]) {
      r.false_alarms.push_back({a["corner"].as<std::string>(), a["finding"].as<std::string>(), a["detected_s"].as<double>()});
    }
    return r;
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(file + ": not a campaign result (" + std::string(e.what()) + ")");
  }
}

}  // namespace bbw::campaign
