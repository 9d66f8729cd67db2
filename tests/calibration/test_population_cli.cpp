// ./bbw population: a small spec recorded to CSVs that ./bbw calibrate reads, with a manifest;
// a bad spec stops with file, line and key.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

namespace {

struct ToolRun {
  int exit_code;
  std::string output;
};

ToolRun run(const std::string& tool, const std::string& args) {
  const std::string cmd = std::string(BBW_BINARY_DIR_FALLBACK) + "/bin/" + tool + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[512];
  while (p && fgets(buf, sizeof buf, p)) out += buf;
  const int status = p ? pclose(p) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

std::string read_file(const fs::path& p) {
  std::ifstream f(p);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

std::string spec(const std::string& extra) {
  return "name: small\nseed: 11\ncount: 3\ntemperatures_C: [28, 54]\nduration_s: 8\nplant_dt_s: 0.001\n"
         "plant: " BBW_SOURCE_DIR_FALLBACK "/config/plant/ecaliper.yaml\n"
         "drive:\n  mode: position\n  segments:\n    - {type: paper_sweep, x_low_rev: 1.0, amplitudes_rev: [2.0, 3.0, 3.0],"
         " period_s: 2.0}\n"
         "ranges:\n  elements: [10, 60]\n  threshold_min_rev: [0.002, 0.05]\n  threshold_span_ratio: [3, 400]\n"
         "  threshold_max_limit_rev: 0.8\n  log_uniform_share: 0.5\n  half_width_kN: [0.5, 2]\n"
         "  force_share_exponent: [-0.5, 1]\n  share_log_sigma: [0, 1]\n  initial_deflection: [-1, 1]\n"
         "  contact_rev: [0.2, 1.0]\n  stiffness_scale: [0.7, 1.3]\n  contact_shift_rev_per_C: [0.002, 0.006]\n"
         "  stiffness_change_per_C: [-0.006, -0.002]\n  load_cell_noise_kN: [0.02, 0.05]\n" + extra;
}

}  // namespace

TEST(PopulationCli, WritesCalibratableRecordingsAndAManifest) {
  const fs::path dir = fs::path(::testing::TempDir()) / "bbw_population_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "spec.yaml") << spec("");
  const ToolRun r = run("bbw_population", (dir / "spec.yaml").string() + " --out " + (dir / "out").string() +
                                          " --members 1:2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("ETA"), std::string::npos) << r.output;  // progress on stderr
  for (const char* f : {"c1_T28.csv", "c1_T54.csv", "c2_T28.csv", "c2_T54.csv", "manifest.json"}) {
    EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
  }
  EXPECT_FALSE(fs::exists(dir / "out" / "c0_T28.csv"));
  const std::string manifest = read_file(dir / "out" / "manifest.json");
  EXPECT_NE(manifest.find("\"thresholds_rev\""), std::string::npos);
  EXPECT_NE(manifest.find("\"initial_deflection\""), std::string::npos);
  EXPECT_NE(manifest.find("c2_T54.csv"), std::string::npos);
  // The same member twice gives the same file (seeded).
  const ToolRun again = run("bbw_population", (dir / "spec.yaml").string() + " --out " + (dir / "again").string() +
                                              " --members 2:1");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(read_file(dir / "out" / "c2_T54.csv"), read_file(dir / "again" / "c2_T54.csv"));
  // ./bbw calibrate reads it with its default columns and scores it against the external sensor.
  const ToolRun cal = run("bbw_calibrate", "--input " + (dir / "out" / "c1_T28.csv").string() + " --out " +
                                           (dir / "cal").string());
  ASSERT_EQ(cal.exit_code, 0) << cal.output;
  EXPECT_NE(cal.output.find("max |error|"), std::string::npos) << cal.output;
  EXPECT_EQ(cal.output.find(" 0 fits accepted"), std::string::npos) << cal.output;
  EXPECT_TRUE(fs::exists(dir / "cal" / "error_time.png"));
}

TEST(PopulationCli, BadSpecNamesFileLineAndKey) {
  const fs::path dir = fs::path(::testing::TempDir()) / "bbw_population_cli_bad";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "spec.yaml") << spec("  elements_colour: [1, 2]\n");
  const ToolRun r = run("bbw_population", (dir / "spec.yaml").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("spec.yaml:27"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ranges.elements_colour"), std::string::npos) << r.output;
  const ToolRun none = run("bbw_population", "--out " + (dir / "out").string());
  EXPECT_EQ(none.exit_code, 2) << none.output;
}
