// PNG plots through gnuplot (a Debian package; ./bbw setup installs gnuplot-nox).
#pragma once

#include <string>

namespace bbw::plot {

// Runs gnuplot on `script` (written to `script_file` for the record, e.g. DIR/fig5.gp).
// The script should set its own terminal ("set terminal pngcairo" or "png") and output.
// Throws std::runtime_error naming the script when gnuplot is missing or fails.
void run_gnuplot(const std::string& script, const std::string& script_file);

// Quotes a path for use inside a gnuplot script.
std::string quote(const std::string& path);

}  // namespace bbw::plot
