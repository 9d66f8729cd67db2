#include "out_dir.hpp"

#include <filesystem>
#include <regex>
#include <stdexcept>
#include <system_error>

namespace bbw::launch {

namespace fs = std::filesystem;

bool is_run_output_name(const std::string& name) {
  static const std::regex own(
      "summary\\.json|report\\.html|report\\.gp(\\.log)?|timeline\\.csv|timeline\\.png|keys\\.(out|err)|"
      "ccu\\.(out|err|stats)|ccu_periods\\.csv|ccu_(FL|FR|RL|RR)\\.csv|(loop|time)_(FL|FR|RL|RR)\\.png|"
      "corner_(FL|FR|RL|RR)(\\.[0-9]+)?\\.(out|err|stats)|corner_(FL|FR|RL|RR)_periods\\.csv|"
      // A vehicle run (issue 15): bbw_vehicle's and bbw_pedal's outputs and plots.
      "(vehicle|pedal)\\.(out|err)|vehicle_truth\\.csv|vehicle\\.json|vehicle_plots\\.gp(\\.log)?|"
      "(speeds|slips|clamp_forces|mu_used|path)\\.png|"
      // a run with a hot-standby CCU (issue 16)
      "ccu_standby\\.(out|err)|ccu_failover\\.stats|corner_(FL|FR|RL|RR)(\\.[0-9]+)?_failover\\.stats");
  return std::regex_match(name, own);
}

OutDirResult prepare_out_dir(const std::string& dir) {
  OutDirResult result;
  std::error_code ec;
  if (!fs::exists(dir, ec)) {
    if (!fs::create_directories(dir, ec) || ec) {
      throw std::invalid_argument("cannot create output directory " + dir + (ec ? ": " + ec.message() : ""));
    }
    return result;
  }
  if (!fs::is_directory(dir, ec)) throw std::invalid_argument("output directory " + dir + " is not a directory");
  std::vector<fs::path> own;
  // The standby CCU's folder of a standby run: only files bbw writes.
  auto own_standby_dir = [&](const fs::directory_entry& e) {
    if (e.path().filename() != "standby" || !e.is_directory(ec)) return false;
    for (const auto& f : fs::directory_iterator(e.path(), ec)) {
      if (!f.is_regular_file(ec) || !is_run_output_name(f.path().filename().string())) return false;
    }
    return true;
  };
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (own_standby_dir(e)) {
      own.push_back(e.path());
      continue;
    }
    if (!e.is_regular_file(ec) || !is_run_output_name(name)) {
      throw std::invalid_argument("output directory " + dir + " holds '" + name +
                                  "', which bbw did not write; use an empty or new directory (nothing was removed)");
    }
    own.push_back(e.path());
  }
  if (ec) throw std::invalid_argument("cannot list output directory " + dir + ": " + ec.message());
  for (const auto& p : own) {
    if (fs::remove_all(p, ec) == 0 || ec) throw std::invalid_argument("cannot remove older " + p.string() + ": " + ec.message());
    result.removed.push_back(p.filename().string());
  }
  return result;
}

}  // namespace bbw::launch
