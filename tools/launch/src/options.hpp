// bbw_launch's command line: parsed and validated before anything starts (Ceres-style validated
// options). The scenario file itself is loaded and checked by load_run().
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "bbw/faults/schedule.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::launch {

extern const char* const kUsage;

struct Options {
  std::string scenario_file, out_dir;
  std::string mode = "lockstep";      // lockstep | realtime
  std::string friction_feedback = "on";
  std::optional<std::string> domain_arg;  // --domain (else BBW_DOMAIN, else a free one)
  double discovery_s = 20.0;
  bool report = true;
  bool secure = false;
  bool allow_large = false;  // accept a run over the size limits (scenario/run_checks.hpp)
  bool standby = false;      // --standby: a hot-standby CCU too (or the scenario's standby: true)
  std::string keys_dir;      // default: keys/ in bbw's data root (bbw/common/data_path.hpp)
  bool help = false;         // -h / --help: print kUsage, start nothing
};

// Throws std::invalid_argument naming the argument at fault.
Options parse_options(int argc, char** argv);

// The domain id of --domain or BBW_DOMAIN; -1 when neither is given (choose a free one).
// Throws std::invalid_argument.
int requested_domain(const Options& o);

struct LoadedRun {
  scenario::Scenario scenario;
  faults::FaultSchedule schedule;
  // The processes the scenario declares (`processes:`), or its default (ccu, ccu_standby with a
  // standby, the corners): the launcher starts exactly these. A vehicle scenario adds "vehicle"
  // and "pedal".
  std::vector<std::string> processes;
};

// The scenario and its fault schedule, checked for a DDS run (four corners, size limits unless
// --allow-large, no CCU restart). Throws std::exception naming the file.
LoadedRun load_run(const Options& o);

}  // namespace bbw::launch
