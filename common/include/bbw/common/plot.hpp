// PNG plots through gnuplot (a Debian package; ./bbw setup installs gnuplot-nox).
#pragma once

#include <string>
#include <vector>

namespace bbw::plot {

// Runs gnuplot on `script` (written to `script_file` for the record, e.g. DIR/fig5.gp; its
// stderr goes to script_file.log). The script sets its own terminal ("set terminal pngcairo")
// and its outputs with "set output " + quote(path) lines. gnuplot is a child that dies with this
// process (PR_SET_PDEATHSIG). The outputs are removed before it runs; when gnuplot is missing,
// fails, or leaves an output missing or empty, every output is removed and std::runtime_error
// names the script, how gnuplot ended, the last line of its log and the plots not written.
void run_gnuplot(const std::string& script, const std::string& script_file);

// The paths of the script's "set output '...'" lines (as written by quote()).
std::vector<std::string> outputs_of(const std::string& script);

// Quotes a path for use inside a gnuplot script.
std::string quote(const std::string& path);

}  // namespace bbw::plot
