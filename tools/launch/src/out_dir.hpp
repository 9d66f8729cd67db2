// The output directory of a run: created when missing; when reused, bbw's own files of an older
// run are removed first, so no file of that run survives beside the new one. A directory that
// holds anything else (a file bbw does not write, a subdirectory) is refused: the launcher never
// deletes what it did not write.
#pragma once

#include <string>
#include <vector>

namespace bbw::launch {

// True for the names bbw_launch and its children write into an output directory
// (summary.json, report.html, ccu.*, ccu_*.csv, corner_*.{out,err,stats,csv}, ...).
bool is_run_output_name(const std::string& name);

struct OutDirResult {
  std::vector<std::string> removed;  // names of older files removed
};

// Creates `dir` or clears bbw's older files from it. Throws std::invalid_argument naming the
// first foreign entry (nothing is removed then) or when `dir` cannot be created.
OutDirResult prepare_out_dir(const std::string& dir);

}  // namespace bbw::launch
