#include "vehicle_summary.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace bbw::launch {

namespace {
std::string read(const std::string& file) {
  std::ifstream f(file);
  if (!f) throw std::runtime_error(file + ": cannot read");
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}
}  // namespace

void merge_vehicle_summary(const std::string& out_dir) {
  const std::string summary_file = out_dir + "/summary.json";
  std::string summary = read(summary_file);
  const std::string vehicle = read(out_dir + "/vehicle.json");
  // Both are one JSON object: the vehicle's members go in before the summary's closing brace.
  const auto open = vehicle.find('{');
  const auto close = vehicle.rfind('}');
  const auto end = summary.rfind('}');
  if (open == std::string::npos || close == std::string::npos || close <= open + 1 || end == std::string::npos) {
    throw std::runtime_error(out_dir + ": summary.json or vehicle.json is not a JSON object");
  }
  std::string members = ",";
  members.append(vehicle, open + 1, close - open - 1);
  summary.insert(end, members);
  std::ofstream f(summary_file, std::ios::trunc);
  f << summary;
  if (!f) throw std::runtime_error(summary_file + ": cannot write");
}

}  // namespace bbw::launch
