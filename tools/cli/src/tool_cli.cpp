#include "bbw/tool_cli/tool_cli.hpp"

#include <iostream>
#include <stdexcept>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/common/data_path.hpp"
#include "bbw/faults/monitor_yaml.hpp"

namespace bbw::tool_cli {

int usage_error(const std::string& program, const std::string& usage, const std::string& why) {
  std::cerr << program << ": " << why << "\n" << usage;
  return 2;
}

std::optional<int> parse(int argc, char** argv, const std::string& program, const std::string& usage, ModelArgs& args,
                         const OwnFlag& own) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const std::function<std::string()> value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    try {
      if (a == "-h" || a == "--help") {
        std::cout << usage;
        return 0;
      }
      if (a == "--calibrator") args.calibrator = value();
      else if (a == "--monitor") args.monitor = value();
      else if (own && own(a, value)) continue;
      else if (!a.empty() && a[0] == '-') return usage_error(program, usage, "unknown argument '" + a + "'");
      else if (args.scenario.empty()) args.scenario = a;
      else return usage_error(program, usage, "one scenario only, got '" + a + "' too");
    } catch (const std::exception& e) {
      return usage_error(program, usage, e.what());
    }
  }
  if (args.scenario.empty()) return usage_error(program, usage, "a scenario file is required");
  return std::nullopt;
}

calibration::CalibratorConfig load_calibrator(const ModelArgs& args) {
  auto c = calibration::load_config(args.calibrator.empty() ? data::path("config/calibrator/robust.yaml") : args.calibrator);
  c.validate();
  return c;
}

faults::MonitorParams load_monitor(const ModelArgs& args) {
  return faults::load_monitor_params(args.monitor.empty() ? data::path("config/faults/monitor.yaml") : args.monitor);
}

}  // namespace bbw::tool_cli
