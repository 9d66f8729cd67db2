// Run statistics exchanged between bbw_corner / bbw_ccu and bbw_launch: one "key=value" per
// line, keys in the order written. Small enough to read without a JSON parser.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace bbw::launch {

class StatsWriter {
 public:
  void set(const std::string& key, const std::string& value) { lines_.emplace_back(key, value); }
  void set(const std::string& key, double value);
  void set(const std::string& key, long long value) { set(key, std::to_string(value)); }
  void set(const std::string& key, unsigned long long value) { set(key, std::to_string(value)); }
  void set(const std::string& key, unsigned long value) { set(key, static_cast<unsigned long long>(value)); }
  void set(const std::string& key, int value) { set(key, static_cast<long long>(value)); }
  void save(const std::string& file) const;  // throws std::runtime_error

 private:
  std::vector<std::pair<std::string, std::string>> lines_;
};

// Throws std::runtime_error naming the file and line when it is missing or malformed.
std::map<std::string, std::string> read_stats(const std::string& file);
double stat_number(const std::map<std::string, std::string>& stats, const std::string& key,
                   const std::string& file);

}  // namespace bbw::launch
