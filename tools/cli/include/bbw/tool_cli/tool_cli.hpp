// The command line the in-process tools share (bbw_inproc, bbw_vehicle_inproc, bbw_loop_check):
// one positional scenario file, --calibrator FILE, --monitor FILE and -h/--help, and the tool's
// own flags through a callback; then the calibrator and monitor those files name, bbw's shipped
// ones (config/calibrator/robust.yaml, config/faults/monitor.yaml) when none is given.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "bbw/calibration/config.hpp"
#include "bbw/faults/fault_monitor.hpp"

namespace bbw::tool_cli {

struct ModelArgs {
  std::string scenario;    // the one positional argument (required)
  std::string calibrator;  // --calibrator FILE ("" for bbw's shipped one)
  std::string monitor;     // --monitor FILE ("" for bbw's shipped one)
};

// A tool's own flag: returns false when `flag` is not one of its own; `value()` takes the flag's
// value (throws std::invalid_argument when there is none). A bad value: throw
// std::invalid_argument with the rule, which becomes a usage error.
using OwnFlag = std::function<bool(const std::string& flag, const std::function<std::string()>& value)>;

// Prints "<program>: <why>" and the usage text to stderr; returns 2.
int usage_error(const std::string& program, const std::string& usage, const std::string& why);

// Parses the command line. Returns the exit code when the tool is to stop now (0 after --help,
// which prints `usage` to stdout; 2 after a usage error), nullopt to go on.
std::optional<int> parse(int argc, char** argv, const std::string& program, const std::string& usage, ModelArgs& args,
                         const OwnFlag& own = {});

// The calibrator (validated) and the monitor parameters `args` names, or the shipped ones.
calibration::CalibratorConfig load_calibrator(const ModelArgs& args);
faults::MonitorParams load_monitor(const ModelArgs& args);

}  // namespace bbw::tool_cli
