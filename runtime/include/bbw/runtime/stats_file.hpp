// One raw key of a stats file, for tests and tools that look at a single counter (the system
// tests, bench_dds_lockstep). The processes write and bbw_launch reads stats files only through
// the typed structs of run_stats.hpp.
#pragma once

#include <map>
#include <string>

namespace bbw::runtime {

// Throws std::runtime_error naming the file and line when it is missing or malformed.
std::map<std::string, std::string> read_stats(const std::string& file);
double stat_number(const std::map<std::string, std::string>& stats, const std::string& key,
                   const std::string& file);

}  // namespace bbw::runtime
