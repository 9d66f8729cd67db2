#include "bbw/common/plot.hpp"

#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace bbw::plot {

std::string quote(const std::string& path) {
  std::string o = "'";
  for (const char c : path) {
    if (c == '\'') o += "''";
    else o += c;
  }
  return o + "'";
}

void run_gnuplot(const std::string& script, const std::string& script_file) {
  {
    std::ofstream f(script_file);
    if (!f) throw std::runtime_error(script_file + ": cannot write gnuplot script");
    f << script;
  }
  std::string cmd = "gnuplot " + quote(script_file) + " 2>" + quote(script_file + ".log");
  const int rc = std::system(cmd.c_str());
  if (rc != 0) {
    throw std::runtime_error("gnuplot failed on " + script_file + " (exit " + std::to_string(rc) +
                             "; see " + script_file + ".log; is gnuplot installed? ./bbw setup)");
  }
}

}  // namespace bbw::plot
