// config/vehicle/sedan.yaml loads; bad input names the file, line, key and rule.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "bbw/vehicle/params_yaml.hpp"

using namespace bbw;

namespace {
std::string source_dir() {
  const char* env = std::getenv("BBW_SOURCE_DIR");
  return env ? env : BBW_SOURCE_DIR_FALLBACK;
}
std::string sedan_text() {
  std::ifstream f(source_dir() + "/config/vehicle/sedan.yaml");
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}
vehicle::VehicleConfig from_text(const std::string& text) {
  config::Reader r = config::Reader::from_string(text, "sedan.yaml");
  return vehicle::read_vehicle_config(r);
}
}  // namespace

TEST(VehicleConfig, ShippedFileLoadsWithThePublishedTyre) {
  const vehicle::VehicleConfig c = vehicle::load_vehicle_config(source_dir() + "/config/vehicle/sedan.yaml");
  EXPECT_DOUBLE_EQ(c.vehicle.tyre.pdx1, 1.1739);
  EXPECT_DOUBLE_EQ(c.vehicle.tyre.pky1, 21.92);
  EXPECT_DOUBLE_EQ(c.vehicle.chassis.wheel_radius_m, 0.344);
  EXPECT_EQ(c.vehicle.surfaces.size(), 4u);
  EXPECT_EQ(c.wheel_speed.teeth, 48);
}

TEST(VehicleConfig, UnknownKeyIsRefusedWithItsLine) {
  std::string t = sedan_text();
  t.replace(t.find("  PCX1:"), 0, "  PCX9: 1.0\n");
  try {
    from_text(t);
    FAIL() << "accepted an unknown key";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.key_path(), "tyre.PCX9");
    EXPECT_GT(e.line(), 1);
  }
}

TEST(VehicleConfig, OutOfRangeAndMissingAreRefused) {
  std::string t = sedan_text();
  const auto pos = t.find("mass_kg: 1093.3");
  t.replace(pos, std::string("mass_kg: 1093.3").size(), "mass_kg: -5");
  EXPECT_THROW(from_text(t), config::ConfigError);
  std::string m = sedan_text();
  const auto p2 = m.find("  PKY1:");
  m.erase(p2, m.find('\n', p2) - p2 + 1);
  try {
    from_text(m);
    FAIL();
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.key_path(), "tyre.PKY1");
  }
  std::string s = sedan_text();
  s.replace(s.find("{name: wet"), 10, "{name: dry");
  EXPECT_THROW(from_text(s), config::ConfigError);
}
