#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "bbw/analyze/cli.hpp"
#include "bbw/analyze/report.hpp"
#include "synthetic.hpp"

using namespace bbw;

TEST(AnalyzeCli, ParsesAndRejects) {
  const auto a = analyze::parse_args({"--input", "f.csv", "--out", "d", "--channels", "A,B", "--truth", "none"});
  EXPECT_EQ(a.input, "f.csv");
  EXPECT_TRUE(a.channels_given);
  EXPECT_EQ(a.channels, (std::vector<std::string>{"A", "B"}));
  EXPECT_EQ(a.truth_col, "none");
  const auto b = analyze::parse_args({"--input", "f.csv", "--out", "d", "--channels", "none"});
  EXPECT_TRUE(b.channels.empty());
  EXPECT_THROW(analyze::parse_args({"--input", "f.csv"}), std::invalid_argument);
  EXPECT_THROW(analyze::parse_args({"--input", "f.csv", "--out", "d", "--bogus", "1"}), std::invalid_argument);
  EXPECT_THROW(analyze::parse_args({"--input"}), std::invalid_argument);
  EXPECT_EQ(analyze::unit_from_column("force_internal_kN"), "kN");
  EXPECT_EQ(analyze::unit_from_column("F_N"), "N");
}

// End to end through the CSV reader and the report writer on a synthetic recording with a
// viscous term: the outputs exist and carry the figures the issue asks for.
TEST(AnalyzeCli, WritesJsonReportAndPlots) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("bbw_analyze_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  analysis::test::SyntheticOptions so;
  so.duration_s = 6.0;
  so.effects = {"viscous_friction"};
  const auto rec = analysis::test::synthetic(so);
  {
    std::ofstream f(dir / "rec.csv");
    f << "time_s,position_rev,force_internal_kN,force_external_kN,temperature_C\n";
    f.precision(10);
    for (std::size_t k = 0; k < rec.time_s.size(); ++k)
      f << rec.time_s[k] << "," << rec.position[k] << "," << rec.force[k] << "," << rec.truth[k] << ","
        << rec.temperature[k] << "\n";
    f << "oops,1,2,3,4\n";
  }
  analyze::CliArgs a = analyze::parse_args({"--input", (dir / "rec.csv").string(), "--out", (dir / "out").string()});
  const auto in = analyze::load_recording(a);
  EXPECT_EQ(in.lines_rejected, 1u);
  EXPECT_EQ(in.truth_col, "force_external_kN");
  EXPECT_EQ(in.temperature_col, "temperature_C");
  EXPECT_TRUE(in.channel_cols.empty());
  EXPECT_EQ(in.force_unit, "kN");
  const analysis::AnalysisOptions o;
  const auto r = analysis::analyze(in.rec, o);
  analyze::write_outputs((dir / "out").string(), in, o, r, true);
  std::ifstream j(dir / "out" / "analysis.json");
  std::stringstream js;
  js << j.rdbuf();
  for (const char* key : {"\"baseline\"", "\"final\"", "\"rms_residual\"", "\"max_residual\"", "\"rms_truth_error\"",
                          "\"max_truth_error\"", "\"force_unit\": \"kN\"", "\"steps\"", "\"rejected\"",
                          "\"unexplained_structure\"", "\"structure_tests\"", "\"name\": \"viscous_friction\"",
                          "\"calibrator_effects\": {", "\"viscous_friction\": true"})
    EXPECT_NE(js.str().find(key), std::string::npos) << key;
  {
    std::ifstream md(dir / "out" / "report.md");
    std::stringstream ms;
    ms << md.rdbuf();
    EXPECT_NE(ms.str().find("effects:\n  viscous_friction: true\n"), std::string::npos) << ms.str();
  }
  for (const char* f : {"report.md", "residual_time.png", "residual_vs_regressor.png", "truth_error_time.png"})
    EXPECT_GT(fs::file_size(dir / "out" / f), 100u) << f;
  fs::remove_all(dir);
}
