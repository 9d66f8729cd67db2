// Issue 4's vehicle stop over real processes: the true clamp force's tracking error with the
// corners' friction-compensated load-cell feedback off and on (bbw_compare_feedback runs
// bbw_launch twice). Domain 195.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>

#include <yaml-cpp/yaml.h>

#include "bbw/runtime/child.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

TEST(FeedbackCompare, CompensatedFeedbackLowersTheVehicleStopsTrackingError) {
  const fs::path dir = fs::temp_directory_path() / ("bbw_system_feedback_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  bbw::runtime::Child child("bbw_compare_feedback",
                           {std::string(BBW_TEST_BINARY_DIR) + "/bin/bbw_compare_feedback",
                            std::string(BBW_TEST_SOURCE_DIR) + "/config/scenarios/vehicle_stop.yaml", "--out",
                            (dir / "out").string(), "--domain", "195"},
                           (dir / "stdout").string(), (dir / "stderr").string(), {});
  auto status = child.wait_until(std::chrono::steady_clock::now() + 150s);
  if (!status) status = child.stop(2000ms);
  ASSERT_TRUE(status->exited && status->code == 0) << "see " << dir;
  const YAML::Node s = YAML::LoadFile((dir / "out" / "summary.json").string());
  ASSERT_EQ(s["corners"].size(), 4u);
  for (const auto& c : s["corners"]) {
    const std::string name = c["corner"].as<std::string>();
    EXPECT_GE(c["fits_accepted"].as<int>(), 3) << name;
    const double off = c["tracking_steady_rms_error_off_kN"].as<double>();
    const double on = c["tracking_steady_rms_error_on_kN"].as<double>();
    // Raw load-cell feedback leaves the key friction (about 1 kN half-width) in the loop;
    // compensated feedback removes most of it.
    EXPECT_LT(on, 0.5 * off) << name << ": holds RMS " << off << " -> " << on;
    EXPECT_LT(on, 0.2) << name;
    EXPECT_LT(c["tracking_rms_error_on_kN"].as<double>(), c["tracking_rms_error_off_kN"].as<double>()) << name;
  }
  fs::remove_all(dir);
}
