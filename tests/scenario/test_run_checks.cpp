// Checks a scenario passes before ./bbw run or ./bbw simulate starts (issue 17): a four-corner
// run's corner names, the size of what a run would write and how long it simulates, and corner
// names safe to use in file names. docs/security.md, "Inputs", lists the limits.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "bbw/scenario/load.hpp"
#include "bbw/scenario/run_checks.hpp"

using namespace bbw;
namespace fs = std::filesystem;

namespace {

std::string source_dir() {
  const char* s = std::getenv("BBW_SOURCE_DIR");
  return s ? s : BBW_TEST_SOURCE_DIR;
}

std::string scenario_text(const std::string& duration, const std::string& dt, const std::string& corners) {
  std::string s = "name: t\nseed: 1\nduration_s: " + duration + "\nplant_dt_s: " + dt +
                  "\nplant: ../plant/ecaliper.yaml\ncorners:\n";
  for (const char c : corners) {
    const std::string n = c == 'a' ? "FL" : c == 'b' ? "FR" : c == 'c' ? "RL" : c == 'd' ? "RR" : std::string(1, c);
    s += "  - name: " + n + "\n    temperature_C: 20\n    drive: {mode: force, breakpoints: [[0, 1]]}\n";
  }
  return s;
}

scenario::Scenario load(const std::string& text) {
  return scenario::load_scenario_string(text, source_dir() + "/config/scenarios/test.yaml");
}

template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "<no ConfigError>";
}

}  // namespace

TEST(RunChecks, PaperRigSweepIsNotAFourCornerRun) {
  const auto s = scenario::load_scenario(source_dir() + "/config/scenarios/paper_rig_sweep.yaml");
  const std::string e = error_of([&] { scenario::check_four_corner_run(s); });
  EXPECT_NE(e.find("paper_rig_sweep.yaml:12: key 'corners[0].name': 'T28' is not a corner of a four-corner run "
                   "(FL, FR, RL, RR)"),
            std::string::npos)
      << e;
  EXPECT_EQ(error_of([&] { scenario::check_four_corner_run(load(scenario_text("1", "0.001", "abcd"))); }),
            "<no ConfigError>");
  EXPECT_EQ(error_of([&] { scenario::check_four_corner_run(load(scenario_text("1", "0.001", "ad"))); }),
            "<no ConfigError>");
  EXPECT_NE(error_of([&] { scenario::check_four_corner_run(load(scenario_text("1", "0.001", "abX"))); })
                .find("test.yaml:13: key 'corners[2].name': 'X' is not a corner of a four-corner run"),
            std::string::npos);
  for (const char* f : {"four_corner_rig.yaml", "vehicle_stop.yaml"}) {
    EXPECT_NO_THROW(scenario::check_four_corner_run(scenario::load_scenario(source_dir() + "/config/scenarios/" + f)))
        << f;
  }
}

TEST(RunChecks, RunSizeEstimateAndLimits) {
  // The case: 1e5 s at 1e-5 s, each within its own range, about 1.4 TB of output.
  const auto huge = load(scenario_text("100000", "0.00001", "abcd"));
  const auto e = scenario::estimate_run(huge);
  EXPECT_DOUBLE_EQ(e.plant_steps, 1.0e10);
  EXPECT_DOUBLE_EQ(e.samples, 4.0e10);
  EXPECT_GT(e.output_bytes, 1.0e13);
  EXPECT_NE(error_of([&] { scenario::check_run_size(huge); })
                .find("test.yaml:3: key 'duration_s': a run of 100000 s is longer than the limit of 3600 s "
                      "(--allow-large accepts it)"),
            std::string::npos);
  // Within the duration limit but too much output: 3000 s at 10 us on four corners.
  const std::string big = error_of([&] { scenario::check_run_size(load(scenario_text("3000", "0.00001", "abcd"))); });
  EXPECT_NE(big.find("the run would write about 312 GB (1.2e+09 samples: 3000 s at plant_dt_s 1e-05 s, 4 corners), "
                     "more than the limit of 2 GB (--allow-large accepts it)"),
            std::string::npos)
      << big;
  // Every shipped scenario is within the limits.
  for (const auto& entry : fs::recursive_directory_iterator(source_dir() + "/config/scenarios")) {
    if (entry.path().extension() != ".yaml" || entry.path().string().find("/faults/") != std::string::npos) continue;
    if (entry.path().string().find("/tuning/") != std::string::npos) continue;
    // Vehicle scenarios have their own loader (tests/vehicle_run, test_every_config).
    if (entry.path().string().find("/vehicle/") != std::string::npos) continue;
    EXPECT_NO_THROW(scenario::check_run_size(scenario::load_scenario(entry.path().string()))) << entry.path();
  }
  scenario::RunLimits tight;
  tight.max_output_bytes = 1.0e6;
  EXPECT_NE(error_of([&] { scenario::check_run_size(load(scenario_text("10", "0.001", "abcd")), tight); })
                .find("more than the limit of 1 MB"),
            std::string::npos);
}

TEST(RunChecks, CornerNamesCannotEscapeTheOutputDirectory) {
  for (const char* bad : {"../../x", "a/b", ".hidden", "", "name with space", "ThisNameIsLongerThanThirtyTwoChars"}) {
    std::string text = scenario_text("1", "0.001", "a");
    text.replace(text.find("name: FL"), 8, std::string("name: '") + bad + "'");
    EXPECT_NE(error_of([&] { load(text); }).find("must be 1 to 32 letters, digits, '_' or '-'"), std::string::npos)
        << bad;
  }
}

// The launcher refuses the paper rig before it starts a process, with the corner's line.
TEST(RunChecks, LauncherRefusesANonFourCornerScenarioBeforeStarting) {
  const fs::path out = fs::path(::testing::TempDir()) / "bbw_run_checks_launch";
  fs::remove_all(out);
  const std::string cmd = std::string(BBW_BINARY_DIR_FALLBACK) + "/bin/bbw_launch " + source_dir() +
                          "/config/scenarios/paper_rig_sweep.yaml --out " + out.string() + " --domain 231 2>&1";
  const auto t0 = std::chrono::steady_clock::now();
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string text;
  char buf[512];
  while (fgets(buf, sizeof buf, p)) text += buf;
  const int status = pclose(p);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2) << text;
  EXPECT_NE(text.find("'T28' is not a corner of a four-corner run (FL, FR, RL, RR)"), std::string::npos) << text;
  EXPECT_FALSE(fs::exists(out / "ccu.out")) << "a process was started";
}
