#include "summary_reader.hpp"

#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace bbw::compare_feedback {

std::map<std::string, Tracking> read_summary(const std::string& file) {
  const YAML::Node root = YAML::LoadFile(file);  // JSON is YAML
  if (!root["corners"] || !root["corners"].IsSequence()) throw std::runtime_error(file + ": no 'corners' list");
  std::map<std::string, Tracking> out;
  for (const auto& c : root["corners"]) {
    const std::string corner = c["corner"] ? c["corner"].as<std::string>() : std::string("?");
    auto number = [&](const char* key) {
      const YAML::Node v = c[key];
      if (!v) throw std::runtime_error(file + ": corner " + corner + ": missing '" + key + "'");
      if (v.IsNull() || v.Scalar() == "null") {
        const YAML::Node why = c["tracking_not_scored_reason"];
        throw std::runtime_error(file + ": corner " + corner + ": '" + key + "' is null (not scored: " +
                                 (why && !why.IsNull() ? why.as<std::string>() : std::string("no reason given")) +
                                 "); nothing to compare");
      }
      return v.as<double>();
    };
    Tracking t;
    t.rms = number("tracking_rms_error_kN");
    t.max = number("tracking_max_abs_error_kN");
    t.steady_rms = number("tracking_steady_rms_error_kN");
    t.steady_max = number("tracking_steady_max_abs_error_kN");
    t.fits = c["fits_accepted"].as<long long>();
    out[corner] = t;
  }
  return out;
}

}  // namespace bbw::compare_feedback
