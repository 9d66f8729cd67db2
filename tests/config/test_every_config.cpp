// Every YAML file under config/ is loaded by the loader its folder names. A file in a folder
// with no loader here fails the test, so a new config folder must bring its loader along.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <map>
#include <string>

#include "bbw/analyze/config_loader.hpp"
#include "bbw/calibration/config_yaml.hpp"
#include "bbw/faults/monitor_yaml.hpp"
#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/plant/params_yaml.hpp"
#include "bbw/scenario/load.hpp"
#include "bbw/scenario/population.hpp"
#include "bbw/brake/brake_yaml.hpp"
#include "bbw/vehicle/params_yaml.hpp"
#include "bbw/vehicle_run/vehicle_scenario.hpp"
#include "spec.hpp"  // tools/campaign: the campaign spec

namespace fs = std::filesystem;

TEST(EveryConfig, EachYamlFileLoadsWithItsFoldersLoader) {
  const char* env = std::getenv("BBW_SOURCE_DIR");
  const fs::path root = fs::path(env ? env : BBW_SOURCE_DIR_FALLBACK) / "config";
  // Longest matching folder prefix wins.
  const std::map<std::string, std::function<void(const std::string&)>> loaders = {
      {"plant", [](const std::string& f) { bbw::plant::load_plant_params(f); }},
      {"scenarios", [](const std::string& f) { bbw::scenario::load_scenario(f); }},
      {"scenarios/faults", [](const std::string& f) { bbw::faults::load_fault_scenario(f); }},
      {"calibrator", [](const std::string& f) { bbw::calibration::load_config(f); }},
      {"analysis", [](const std::string& f) { bbw::analyze::load_options_file(f); }},
      {"faults", [](const std::string& f) { bbw::faults::load_monitor_params(f); }},
      {"population", [](const std::string& f) { bbw::scenario::load_population_spec(f); }},
      // Issue 15: the vehicle and the CCU's brake functions; vehicle scenarios and their calipers.
      {"vehicle", [](const std::string& f) {
         if (fs::path(f).filename() == "brake_control.yaml") bbw::brake::load_brake_control(f);
         else bbw::vehicle::load_vehicle_config(f);
       }},
      {"scenarios/vehicle", [](const std::string& f) { bbw::vehicle_run::load_vehicle_scenario(f); }},
      {"scenarios/vehicle/corners", [](const std::string& f) { bbw::faults::load_fault_scenario(f); }},
      {"campaigns", [](const std::string& f) { bbw::campaign::load_campaign_spec(f); }},
  };
  int loaded = 0;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file()) continue;
    const auto ext = entry.path().extension().string();
    if (ext != ".yaml" && ext != ".yml") continue;
    const std::string rel = fs::relative(entry.path().parent_path(), root).string();
    const std::function<void(const std::string&)>* loader = nullptr;
    std::size_t best = 0;
    for (const auto& [folder, fn] : loaders) {
      if ((rel == folder || rel.rfind(folder + "/", 0) == 0) && folder.size() > best) {
        best = folder.size();
        loader = &fn;
      }
    }
    ASSERT_NE(loader, nullptr) << entry.path() << ": no loader for folder config/" << rel;
    EXPECT_NO_THROW((*loader)(entry.path().string())) << entry.path();
    ++loaded;
  }
  EXPECT_GE(loaded, 20);
}
