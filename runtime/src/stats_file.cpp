#include "bbw/runtime/stats_file.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace bbw::runtime {

std::map<std::string, std::string> read_stats(const std::string& file) {
  std::ifstream f(file);
  if (!f) throw std::runtime_error(file + ": cannot read (did the process finish?)");
  std::map<std::string, std::string> out;
  std::string line;
  int n = 0;
  while (std::getline(f, line)) {
    ++n;
    if (line.empty()) continue;
    const auto eq = line.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw std::runtime_error(file + ":" + std::to_string(n) + ": expected key=value");
    }
    out[line.substr(0, eq)] = line.substr(eq + 1);
  }
  return out;
}

double stat_number(const std::map<std::string, std::string>& stats, const std::string& key,
                   const std::string& file) {
  const auto it = stats.find(key);
  if (it == stats.end()) throw std::runtime_error(file + ": missing '" + key + "'");
  char* end = nullptr;
  const double v = std::strtod(it->second.c_str(), &end);
  if (it->second.empty() || *end != '\0') {
    throw std::runtime_error(file + ": '" + key + "' is not a number: " + it->second);
  }
  return v;
}

}  // namespace bbw::runtime
